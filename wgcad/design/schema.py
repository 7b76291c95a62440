"""Design files: frozen dataclasses built from TOML, one table per dataclass, every field rule checked in one place."""

from __future__ import annotations

import math
import typing
from dataclasses import MISSING, dataclass, fields, replace

from ..errors import DesignError, close_matches
from ..numbers import read_float, read_int
from .imperfections import ImperfectionsSpec
from .load import BearingSpec, LoadSpec, MaterialSpec
from .parts import parse_parts
from .rules import WHEN_BUILT, Rel, check_bounds, show
from .rules import key as _key
from .sectors import SectorsSpec, validate_sectors
from .supports import SupportsSpec
from .teeth import GearSpec, ToothFormSpec

__all__ = [
    "DriveSpec",
    "ToothFormSpec",
    "GearSpec",
    "GeneratorSpec",
    "Design",
    "parse_design",
    "validate",
    "with_changes",
    "LAW_NAMES",
]

#: generator laws selectable in ``generator.law`` (docs/models.md 3); internal
#: deformation accepts all but ``external_ring``, external deformation only it
LAW_NAMES = ("harmonic", "disc", "four_force", "ellipse", "external_ring")
_BETA_LAWS = ("disc", "four_force", "external_ring")


@dataclass(frozen=True, slots=True)
class DriveSpec:
    """``[drive]``: the pair of gears and how the drive is used."""

    name: str = _key(
        "name printed in summaries and pictures",
        rule="1 to 200 characters, one line",
        why="it is printed on one line of the summary and in picture titles",
    )
    module: float = _key(
        "module m",
        unit="mm",
        lo=0.02,
        hi=20.0,
        rule="> 0",
        why="fine-module gears start near 0.05 mm and harmonic drives use 0.1-1.5 mm; "
        "outside [0.02, 20] mm the 1 um default chord tolerance is coarser than the teeth "
        "or the outlines need millions of vertices",
    )
    z_flex: int = _key(
        "teeth of the flexspline z_g",
        unit="teeth",
        lo=8,
        hi=3000,
        rule=">= 8",
        why="below 8 teeth involutes undercut whatever the shift; catalogue harmonic drives "
        "have 50-700 teeth, 3000 leaves a wide margin and keeps outlines and audits in memory",
    )
    z_rigid: int = _key(
        "teeth of the rigid gear z_b",
        unit="teeth",
        lo=8,
        hi=3000,
        rule="z_rigid - z_flex (external deformation: z_flex - z_rigid) a positive multiple of waves; "
        "the teeth must meet on the major axis" + WHEN_BUILT,
        why="as z_flex; a rigid gear so much larger than the flexspline that the teeth never "
        "meet is refused when the drive is built",
    )
    face_width: float = _key(
        "toothed face width b_w",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=Rel("d_flex", lambda c: c["d_flex"]),
        why="harmonic drives have b_w/d of 0.1-0.3; wider than the pitch diameter the plane "
        "cross-section model of the rim (docs/models.md 3.1) no longer holds",
    )
    waves: int = _key(
        "waves n_w of the generator",
        unit="",
        lo=2,
        hi=8,
        default=2,
        why="one wave only shifts the rim off-centre; drives use 2 or 3, and the laws other than "
        "harmonic have exactly 2",
    )
    deformation: str = _key(
        '"internal": generator inside; "external": ring washers outside [S3]',
        choices=("internal", "external"),
        default="internal",
    )
    fixed: str = _key("the member held still", choices=("rigid", "flexspline"), default="rigid")
    rotation: str = _key("generator direction seen from the open end", choices=("ccw", "cw"), default="ccw")


@dataclass(frozen=True, slots=True)
class GeneratorSpec:
    """``[generator]``: the wave generator and its deformation law (docs/models.md 3)."""

    law: str = _key(
        "deformation law of the neutral line",
        choices=LAW_NAMES,
        default="harmonic",
        rule="external deformation: external_ring only; internal: all others",
    )
    w0_coef: float = _key(
        "radial deformation on the major axis W0 / m",
        lo=0.0,
        lo_open=True,
        hi=5.0,
        default=1.0,
        rule="W0 < r_m / 4 (checked when the law is built)",
        why="W0 is about k m for a tooth difference of k waves; the ring model of docs/models.md 3.1 "
        "needs W0 small against the rim radius",
    )
    beta_deg: float | None = _key(
        "disc wrap / force half-angle beta",
        unit="deg",
        lo=0.0,
        hi=90.0,
        lo_open=True,
        hi_open=True,
        default=None,
        default_doc="none; required by disc, four_force, external_ring",
        rule="only for disc, four_force, external_ring; four_force: not in (40.71, 49.29)",
        why="an angle inside a quarter wave",
    )
    offset: float = _key(
        "ellipse law: neutral line = the cam ellipse offset outward by this",
        unit="mm",
        lo=0.0,
        hi=Rel("r_flex / 2", lambda c: 0.5 * c["r_flex"]),
        default=0.0,
        rule="only for the ellipse law",
        why="the offset is the bearing and half the rim around the cam: a fraction of the radius",
    )
    cone_length: float | None = _key(
        "cup length l, diaphragm to open end (coning); none = no coning",
        unit="mm",
        lo=0.0,
        lo_open=True,
        hi=Rel("10 d_flex", lambda c: 10.0 * c["d_flex"]),
        default=None,
        default_doc="none (no coning)",
        rule="together with generator_z; at least drive.face_width",
        why="the toothed face lies on the cup; cups are 0.5-1.3 d long",
    )
    generator_z: float | None = _key(
        "generator centre line z_h from the open end",
        unit="mm",
        lo=0.0,
        hi=Rel("cone_length / 2", lambda c: 0.5 * c["cone_length"]),
        default=None,
        default_doc="none (no coning)",
        rule="together with cone_length",
        why="W0 at the open end is W0 l / (l - z_h) (docs/models.md 3.1): z_h <= l/2 keeps it "
        "within 2 W0; generators sit near the open end",
    )


@dataclass(frozen=True, slots=True)
class Design:
    """A whole design file."""

    drive: DriveSpec
    tooth: ToothFormSpec
    flexspline: GearSpec
    rigid: GearSpec
    generator: GeneratorSpec
    source: str = "<memory>"
    sectors: SectorsSpec = SectorsSpec()  # [sectors]: sectored rigid gear (docs/models.md 2.3); empty = plain
    material: MaterialSpec = MaterialSpec()  # [material], [bearing], [load]: design/load.py
    bearing: BearingSpec = BearingSpec()
    load: LoadSpec = LoadSpec()
    supports: SupportsSpec = SupportsSpec()  # [supports]: design/supports.py
    imperfections: ImperfectionsSpec = ImperfectionsSpec()  # optional table, docs/models.md 6.2

    @property
    def module(self) -> float:
        return self.drive.module

    @property
    def w0(self) -> float:
        """W0, mm."""
        return self.generator.w0_coef * self.drive.module

    @property
    def c_star(self) -> float:
        c = self.tooth.clearance_coef
        if c is None:
            return 0.1 if self.tooth.form == "cycloidal" else 0.25
        return c

    @property
    def external(self) -> bool:
        """True for the external-deformation configuration [S3]."""
        return self.drive.deformation == "external"


TABLES: dict[str, type] = {
    "drive": DriveSpec,
    "tooth": ToothFormSpec,
    "flexspline": GearSpec,
    "rigid": GearSpec,
    "generator": GeneratorSpec,
    "sectors": SectorsSpec,
    "material": MaterialSpec,
    "bearing": BearingSpec,
    "load": LoadSpec,
    "supports": SupportsSpec,
    "imperfections": ImperfectionsSpec,
}
OPTIONAL_TABLES = ("tooth", "sectors", "material", "bearing", "load", "supports", "imperfections")
#: tables validated by other modules (``[parts]``: wgcad.design.parts), passed over here
_OTHER_TABLES = ("parts",)


def base_type(tp) -> tuple[type, bool]:
    """(type, optional) from an annotation string/typing object."""
    if isinstance(tp, str):
        tp = eval(tp, {"float": float, "int": int, "str": str, "None": type(None)})  # noqa: S307 - own annotations
    args = typing.get_args(tp)
    if args:
        inner = [a for a in args if a is not type(None)]
        return inner[0], True
    return tp, False


def _coerce(table: str, key: str, value, tp):
    base, optional = base_type(tp)
    where = f"{table}.{key}"
    if base is float:
        return read_float(where, value)
    if base is int:
        return read_int(where, value)
    if base is str:
        if not isinstance(value, str):
            raise DesignError(where, f"must be a string, got {type(value).__name__} {show(value)}")
        return value
    raise AssertionError(base)  # pragma: no cover


def _build(table: str, cls: type, data) -> object:
    if hasattr(cls, "from_table"):  # tables with lists parse themselves (design/sectors.py)
        return cls.from_table(table, data)
    if not isinstance(data, dict):
        raise DesignError(table, f"must be a table [{table}], got {type(data).__name__}")
    known = {f.name: f for f in fields(cls)}
    for key in data:
        if key not in known:
            near = close_matches(key, known)
            hint = f"; did you mean '{near[0]}'?" if near else f"; valid keys: {', '.join(known)}"
            raise DesignError(f"{table}.{key}", f"unknown key{hint}")
    kwargs = {}
    for name, f in known.items():
        if name in data:
            kwargs[name] = _coerce(table, name, data[name], f.type)
        elif f.default is MISSING:
            raise DesignError(f"{table}.{name}", "is required")
    return cls(**kwargs)


def _choice(where: str, value: str, choices) -> None:
    if value not in choices:
        raise DesignError(where, f"must be one of {', '.join(choices)}; got '{value}'")


def _positive(where: str, value: float) -> None:
    if not value > 0:
        raise DesignError(where, f"must be > 0, got {value:g}")


def _validate_gear(d: Design, name: str) -> None:
    """The field rules of ``[flexspline]`` or ``[rigid]`` (``name``)."""
    dr, g = d.drive, d.generator
    gs: GearSpec = getattr(d, name)
    if gs.conjugate_z is not None and gs.flanks != "conjugate":
        raise DesignError(f"{name}.conjugate_z", "is used only with flanks = 'conjugate'")
    if gs.conjugate_clearance_um and gs.flanks != "conjugate":
        raise DesignError(f"{name}.conjugate_clearance_um", "is used only with flanks = 'conjugate'")
    _choice(f"{name}.face_modification", gs.face_modification, ("none", "depth", "linear"))
    if gs.face_modification != "none":
        if name != "flexspline":
            raise DesignError(f"{name}.face_modification", "only the flexspline's teeth are modified along the face")
        if g.cone_length is None or dr.deformation != "internal":
            raise DesignError(
                f"{name}.face_modification",
                "needs a coned cup (generator.cone_length) and internal deformation: it compensates coning",
            )
    if (gs.face_taper_um_per_mm is None) != (gs.face_modification != "linear"):
        raise DesignError(f"{name}.face_taper_um_per_mm", "is given exactly when face_modification = 'linear'")
    _positive(f"{name}.rim_thickness", gs.rim_thickness)
    if gs.fillet_coef < 0:
        raise DesignError(f"{name}.fillet_coef", f"must be >= 0, got {gs.fillet_coef:g}")
    for key in ("tip_radius", "root_radius"):
        val = getattr(gs, key)
        if val is not None:
            _positive(f"{name}.{key}", val)
    if abs(gs.thinning) >= 0.5 * math.pi * dr.module:
        raise DesignError(
            f"{name}.thinning",
            f"must be smaller than half the pitch ({0.5 * math.pi * dr.module:.4f} mm), got {gs.thinning:g}",
        )


def validate(d: Design) -> Design:
    """Check every field rule of a design; return it unchanged or raise :class:`DesignError`.

    Derived-geometry rules (pointed or undercut teeth, fillets that do not
    fit, tip inside root) are checked when the gears are built
    (:func:`wgcad.drive.build_drive`), which :func:`load_design` also does.
    """
    dr, t, g = d.drive, d.tooth, d.generator
    if not 1 <= len(dr.name) <= 200 or any(ord(ch) < 32 for ch in dr.name):
        raise DesignError("drive.name", f"must be 1 to 200 characters on one line, got {show(dr.name)}")
    _positive("drive.module", dr.module)
    for key in ("z_flex", "z_rigid"):
        z = getattr(dr, key)
        if z < 8:
            raise DesignError(f"drive.{key}", f"must be at least 8 teeth, got {z}")
    if dr.waves < 2:
        # one wave only shifts the rim off-centre; it does not deform it
        raise DesignError("drive.waves", f"must be >= 2, got {dr.waves}")
    # every absolute bound before any rule that combines fields (docs/design-keys.md)
    check_bounds(d, TABLES, passes=(0,))
    _positive("drive.face_width", dr.face_width)
    _choice("drive.deformation", dr.deformation, ("internal", "external"))
    _choice("drive.fixed", dr.fixed, ("rigid", "flexspline"))
    _choice("drive.rotation", dr.rotation, ("ccw", "cw"))
    # docs/models.md 1: z_b - z_g = k n_w, k >= 1 (external deformation: z_g - z_b)
    diff = dr.z_rigid - dr.z_flex if dr.deformation == "internal" else dr.z_flex - dr.z_rigid
    expr = "z_rigid - z_flex" if dr.deformation == "internal" else "z_flex - z_rigid"
    if diff <= 0 or diff % dr.waves:
        raise DesignError("drive.z_rigid", f"{expr} = {diff} must be a positive multiple of drive.waves = {dr.waves}")
    _choice("tooth.form", t.form, ("involute", "cycloidal", "double_arc"))
    for key in ("convex_radius_coef", "concave_radius_coef", "tangent_angle_deg", "tangent_length_coef"):
        if getattr(t, key) is not None and t.form != "double_arc":
            raise DesignError(f"tooth.{key}", "is used only with form = 'double_arc'")
    if not 5.0 <= t.pressure_angle_deg <= 45.0:
        raise DesignError("tooth.pressure_angle_deg", f"must be in [5, 45] degrees, got {t.pressure_angle_deg:g}")
    _positive("tooth.addendum_coef", t.addendum_coef)
    if t.clearance_coef is not None and t.clearance_coef < 0:
        raise DesignError("tooth.clearance_coef", f"must be >= 0, got {t.clearance_coef:g}")
    if d.flexspline.flanks != "form":
        raise DesignError("flexspline.flanks", "only the rigid gear's flanks can be made conjugate (give 'form')")
    if d.rigid.flanks == "conjugate" and dr.deformation != "internal":
        raise DesignError("rigid.flanks", "conjugate flanks are built for internal deformation only")
    for name in ("flexspline", "rigid"):
        _validate_gear(d, name)
    laws = ("external_ring",) if dr.deformation == "external" else tuple(x for x in LAW_NAMES if x != "external_ring")
    _choice("generator.law", g.law, laws)
    if g.law != "harmonic" and dr.waves != 2:
        raise DesignError("drive.waves", f"the {g.law} law has two waves; got {dr.waves}")
    _positive("generator.w0_coef", g.w0_coef)
    if g.law in _BETA_LAWS:
        if g.beta_deg is None:
            raise DesignError("generator.beta_deg", f"is required for the {g.law} law")
        if not 0.0 < g.beta_deg < 90.0:
            raise DesignError("generator.beta_deg", f"must be in (0, 90) degrees, got {g.beta_deg:g}")
    if g.offset < 0:
        raise DesignError("generator.offset", f"must be >= 0, got {g.offset:g}")
    if g.beta_deg is not None and g.law not in _BETA_LAWS:
        raise DesignError(
            "generator.beta_deg", f"is not used by the {g.law} law (only by {', '.join(_BETA_LAWS)}); remove it"
        )
    if g.offset != 0.0 and g.law != "ellipse":
        raise DesignError("generator.offset", f"is used only by the ellipse law, not by {g.law}; remove it")
    if (g.cone_length is None) != (g.generator_z is None):
        raise DesignError("generator.cone_length", "cone_length and generator_z go together (both or neither)")
    if g.cone_length is not None:
        _positive("generator.cone_length", g.cone_length)
        if not 0.0 <= g.generator_z < g.cone_length:
            raise DesignError(
                "generator.generator_z", f"must be in [0, cone_length = {g.cone_length:g}) mm, got {g.generator_z:g}"
            )
        if dr.face_width > g.cone_length:
            raise DesignError(
                "drive.face_width",
                f"face width {dr.face_width:g} mm exceeds generator.cone_length {g.cone_length:g} mm",
            )
    # the bounds relative to the design's own sizes (docs/design-keys.md)
    check_bounds(d, TABLES, passes=(1,))
    validate_sectors(d.sectors, dr.z_flex, dr.z_rigid, dr.waves)
    # [material], [bearing], [load] and [imperfections] have no rule beyond their keys' bounds (checked above)
    return d


def parse_design(data: dict, source: str = "<memory>") -> Design:
    """Build and validate a :class:`Design` from a TOML-like dict."""
    if not isinstance(data, dict):
        raise DesignError("<file>", "must be a TOML document with tables")
    for key in data:
        if key not in TABLES and key not in _OTHER_TABLES:
            near = close_matches(key, TABLES)
            hint = f"; did you mean [{near[0]}]?" if near else f"; valid tables: {', '.join(TABLES)}"
            raise DesignError(key, f"unknown table{hint}")
    parts = {}
    for name, cls in TABLES.items():
        if name not in data:
            if name in OPTIONAL_TABLES:
                parts[name] = cls()
                continue
            raise DesignError(name, f"table [{name}] is required")
        parts[name] = _build(name, cls, data[name])
    # [parts] is read by the part set and, for the diaphragm the flexspline tilts on, by the loaded model: a bad
    # key is refused with the design, not when one of them first reads it
    parse_parts(data.get("parts"))
    return validate(Design(source=source, **parts))


def with_changes(d: Design, **tables) -> Design:
    """A copy of ``d`` with some fields changed, e.g. ``with_changes(d, generator={"w0_coef": 1.3})``; validated."""
    parts = {}
    for name, changes in tables.items():
        parts[name] = replace(getattr(d, name), **changes)
    return validate(replace(d, **parts))
