"""Design files: frozen dataclasses built from TOML, one table per dataclass, every field rule checked in one place."""

from __future__ import annotations

import difflib
import math
import tomllib
import typing
from dataclasses import MISSING, dataclass, fields, replace
from pathlib import Path

from ..errors import DesignError, InputFileError

__all__ = [
    "DriveSpec",
    "ToothFormSpec",
    "GearSpec",
    "GeneratorSpec",
    "Design",
    "load_design",
    "parse_design",
    "validate",
    "with_changes",
    "LAW_NAMES",
]

#: generator laws selectable in ``generator.law`` (theory.md 3); internal
#: deformation accepts all but ``external_ring``, external deformation only it
LAW_NAMES = ("harmonic", "disc", "four_force", "ellipse", "external_ring")
_BETA_LAWS = ("disc", "four_force", "external_ring")


@dataclass(frozen=True)
class DriveSpec:
    """``[drive]``: the pair of gears and how the drive is used."""

    name: str
    module: float  # mm
    z_flex: int
    z_rigid: int
    face_width: float  # mm, b_w
    waves: int = 2  # n_w
    deformation: str = "internal"  # "internal": generator inside; "external": ring washers outside [S3]
    fixed: str = "rigid"  # the member held still: "rigid" or "flexspline"
    rotation: str = "ccw"  # generator direction seen from the open end: "ccw" or "cw"


@dataclass(frozen=True)
class ToothFormSpec:
    """``[tooth]``: tooth form shared by both gears (theory.md 2)."""

    form: str = "involute"  # "involute" | "cycloidal"
    pressure_angle_deg: float = 20.0
    addendum_coef: float = 1.0  # h_a*
    clearance_coef: float | None = None  # c*; default 0.25 involute, 0.1 cycloidal


@dataclass(frozen=True)
class GearSpec:
    """``[flexspline]`` / ``[rigid]``: one gear's teeth and body."""

    rim_thickness: float  # mm; flexspline: rim under the teeth h1; rigid: wall beyond the root circle
    shift: float = 0.0  # x
    tip_radius: float | None = None  # mm, overrides the standard tip
    root_radius: float | None = None  # mm, overrides the standard root
    thinning: float = 0.0  # mm, tooth-thickness allowance at the pitch circle (backlash)
    fillet_coef: float = 0.25  # root fillet radius / m


@dataclass(frozen=True)
class GeneratorSpec:
    """``[generator]``: the wave generator and its deformation law (theory.md 3)."""

    law: str = "harmonic"
    w0_coef: float = 1.0  # W0 / m
    beta_deg: float | None = None  # disc wrap / force half-angle
    offset: float = 0.0  # mm, ellipse law: neutral line = ellipse offset outward by this
    cone_length: float | None = None  # mm, l: diaphragm to open end (cup coning); none = no coning
    generator_z: float | None = None  # mm, z_h: generator centre line from the open end


@dataclass(frozen=True)
class Design:
    """A whole design file."""

    drive: DriveSpec
    tooth: ToothFormSpec
    flexspline: GearSpec
    rigid: GearSpec
    generator: GeneratorSpec
    source: str = "<memory>"

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
            return 0.25 if self.tooth.form == "involute" else 0.1
        return c

    @property
    def external(self) -> bool:
        """True for the external-deformation configuration [S3]."""
        return self.drive.deformation == "external"


_TABLES: dict[str, type] = {
    "drive": DriveSpec,
    "tooth": ToothFormSpec,
    "flexspline": GearSpec,
    "rigid": GearSpec,
    "generator": GeneratorSpec,
}
_OPTIONAL_TABLES = ("tooth",)
#: tables validated by other modules (``[parts]``: wgcad.design.parts), passed over here
_OTHER_TABLES = ("parts",)


def _base_type(tp) -> tuple[type, bool]:
    """(type, optional) from an annotation string/typing object."""
    if isinstance(tp, str):
        tp = eval(tp, {"float": float, "int": int, "str": str, "None": type(None)})  # noqa: S307 - own annotations
    args = typing.get_args(tp)
    if args:
        inner = [a for a in args if a is not type(None)]
        return inner[0], True
    return tp, False


def _coerce(table: str, key: str, value, tp):
    base, optional = _base_type(tp)
    where = f"{table}.{key}"
    if base is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise DesignError(where, f"must be a number, got {type(value).__name__} {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise DesignError(where, f"must be finite, got {value}")
        return value
    if base is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise DesignError(where, f"must be a whole number, got {type(value).__name__} {value!r}")
        return value
    if base is str:
        if not isinstance(value, str):
            raise DesignError(where, f"must be a string, got {type(value).__name__} {value!r}")
        return value
    raise AssertionError(base)  # pragma: no cover


def _build(table: str, cls: type, data) -> object:
    if not isinstance(data, dict):
        raise DesignError(table, f"must be a table [{table}], got {type(data).__name__}")
    known = {f.name: f for f in fields(cls)}
    for key in data:
        if key not in known:
            near = difflib.get_close_matches(key, known, n=1)
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


def validate(d: Design) -> Design:
    """Check every field rule of a design; return it unchanged or raise :class:`DesignError`.

    Derived-geometry rules (pointed or undercut teeth, fillets that do not
    fit, tip inside root) are checked when the gears are built
    (:func:`wgcad.drive.build_drive`), which :func:`load_design` also does.
    """
    dr, t, g = d.drive, d.tooth, d.generator
    _positive("drive.module", dr.module)
    for key in ("z_flex", "z_rigid"):
        z = getattr(dr, key)
        if z < 8:
            raise DesignError(f"drive.{key}", f"must be at least 8 teeth, got {z}")
    if dr.waves < 2:
        # one wave only shifts the rim off-centre; it does not deform it
        raise DesignError("drive.waves", f"must be >= 2, got {dr.waves}")
    _positive("drive.face_width", dr.face_width)
    _choice("drive.deformation", dr.deformation, ("internal", "external"))
    _choice("drive.fixed", dr.fixed, ("rigid", "flexspline"))
    _choice("drive.rotation", dr.rotation, ("ccw", "cw"))
    # theory.md 1: z_b - z_g = k n_w, k >= 1 (external deformation: z_g - z_b)
    diff = dr.z_rigid - dr.z_flex if dr.deformation == "internal" else dr.z_flex - dr.z_rigid
    expr = "z_rigid - z_flex" if dr.deformation == "internal" else "z_flex - z_rigid"
    if diff <= 0 or diff % dr.waves:
        raise DesignError("drive.z_rigid", f"{expr} = {diff} must be a positive multiple of drive.waves = {dr.waves}")
    _choice("tooth.form", t.form, ("involute", "cycloidal"))
    if not 5.0 <= t.pressure_angle_deg <= 45.0:
        raise DesignError("tooth.pressure_angle_deg", f"must be in [5, 45] degrees, got {t.pressure_angle_deg:g}")
    _positive("tooth.addendum_coef", t.addendum_coef)
    if t.clearance_coef is not None and t.clearance_coef < 0:
        raise DesignError("tooth.clearance_coef", f"must be >= 0, got {t.clearance_coef:g}")
    for name in ("flexspline", "rigid"):
        gs: GearSpec = getattr(d, name)
        _positive(f"{name}.rim_thickness", gs.rim_thickness)
        if gs.fillet_coef < 0:
            raise DesignError(f"{name}.fillet_coef", f"must be >= 0, got {gs.fillet_coef:g}")
        for key in ("tip_radius", "root_radius"):
            val = getattr(gs, key)
            if val is not None:
                _positive(f"{name}.{key}", val)
        if abs(gs.thinning) >= 0.5 * math.pi * dr.module:
            raise DesignError(f"{name}.thinning", f"must be smaller than half the pitch ({0.5 * math.pi * dr.module:.4f} mm), got {gs.thinning:g}")
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
        raise DesignError("generator.beta_deg", f"is not used by the {g.law} law (only by {', '.join(_BETA_LAWS)}); remove it")
    if g.offset != 0.0 and g.law != "ellipse":
        raise DesignError("generator.offset", f"is used only by the ellipse law, not by {g.law}; remove it")
    if (g.cone_length is None) != (g.generator_z is None):
        raise DesignError("generator.cone_length", "cone_length and generator_z go together (both or neither)")
    if g.cone_length is not None:
        _positive("generator.cone_length", g.cone_length)
        if not 0.0 <= g.generator_z < g.cone_length:
            raise DesignError("generator.generator_z", f"must be in [0, cone_length = {g.cone_length:g}) mm, got {g.generator_z:g}")
        if dr.face_width > g.cone_length:
            raise DesignError("drive.face_width", f"face width {dr.face_width:g} mm exceeds generator.cone_length {g.cone_length:g} mm")
    return d


def parse_design(data: dict, source: str = "<memory>") -> Design:
    """Build and validate a :class:`Design` from a TOML-like dict."""
    if not isinstance(data, dict):
        raise DesignError("<file>", "must be a TOML document with tables")
    for key in data:
        if key not in _TABLES and key not in _OTHER_TABLES:
            near = difflib.get_close_matches(key, _TABLES, n=1)
            hint = f"; did you mean [{near[0]}]?" if near else f"; valid tables: {', '.join(_TABLES)}"
            raise DesignError(key, f"unknown table{hint}")
    parts = {}
    for name, cls in _TABLES.items():
        if name not in data:
            if name in _OPTIONAL_TABLES:
                parts[name] = cls()
                continue
            raise DesignError(name, f"table [{name}] is required")
        parts[name] = _build(name, cls, data[name])
    return validate(Design(source=source, **parts))


def load_design(path) -> Design:
    """Read, parse and validate a design file (field rules; the derived geometry is
    checked by :func:`wgcad.drive.build_drive`).

    Raises
    ------
    InputFileError
        Missing or unreadable file, invalid TOML.
    DesignError
        A field or derived-geometry rule is broken.
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise InputFileError(f"{p}: design file not found") from None
    except OSError as e:
        raise InputFileError(f"{p}: cannot read design file ({e.strerror})") from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise InputFileError(f"{p}: not valid TOML ({e})") from None
    return parse_design(data, source=str(p))


def with_changes(d: Design, **tables) -> Design:
    """A copy of ``d`` with some fields changed, e.g. ``with_changes(d, generator={"w0_coef": 1.3})``; validated."""
    parts = {}
    for name, changes in tables.items():
        parts[name] = replace(getattr(d, name), **changes)
    return validate(replace(d, **parts))
