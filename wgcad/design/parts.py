"""The optional ``[parts]`` table: sizes of the cup, wave-generator plug and rigid-gear body, with defaults derived from the gear size."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from ..errors import DesignError, InputFileError, close_matches
from ..numbers import read_float, show_value
from .bolting import METRIC, RULE, SLIP_SAFETY, carry, choose_bolts

__all__ = [
    "PartsSpec",
    "PartSizes",
    "parse_parts",
    "load_parts",
    "part_sizes",
    "diaphragm_geometry",
    "MAX_PART_MM",
    "MAX_BOLTS",
    "PARTS_DOC",
]


@dataclass(frozen=True, slots=True)
class PartsSpec:
    """``[parts]``: every key optional (mm, counts); ``None`` means "derive from the gear size" (:func:`part_sizes`)."""

    cup_length: float | None = None  # open end to the diaphragm's outer face
    shell_thickness: float | None = None  # cup wall between the toothed rim and the diaphragm
    diaphragm_thickness: float | None = None
    hub_bore_diameter: float | None = None  # bore of the diaphragm
    cup_bolt_circle_diameter: float | None = None
    cup_bolt_count: int | None = None
    cup_bolt_hole_diameter: float | None = None
    bearing_thickness: float | None = None  # radial section of the flexible bearing (races + balls)
    bearing_width: float | None = None  # axial
    plug_bore_diameter: float | None = None
    flange_outer_diameter: float | None = None  # rigid gear's mounting flange
    flange_thickness: float | None = None
    flange_bolt_circle_diameter: float | None = None
    flange_bolt_count: int | None = None
    flange_bolt_hole_diameter: float | None = None


#: largest size any [parts] length may have, mm: ten metres, far beyond any strain-wave drive built
#: (the largest catalogue units are about 1 m); it keeps absurd values from reaching the CAD kernel
MAX_PART_MM = 10_000.0
#: bolt counts: one to one per degree
MAX_BOLTS = 360

#: what each [parts] key is (for the key reference, docs/design-keys.md)
PARTS_DOC = {
    "cup_length": "flexspline cup: open end to the diaphragm's outer face",
    "shell_thickness": "cup wall between the toothed rim and the diaphragm",
    "diaphragm_thickness": "the cup's bottom",
    "hub_bore_diameter": "bore of the diaphragm",
    "cup_bolt_circle_diameter": "bolt circle on the diaphragm",
    "cup_bolt_count": "holes on that circle",
    "cup_bolt_hole_diameter": "their diameter",
    "bearing_thickness": "radial section of the flexible bearing (races and balls)",
    "bearing_width": "axial width of the flexible bearing",
    "plug_bore_diameter": "bore of the wave-generator plug",
    "flange_outer_diameter": "rigid gear's mounting flange",
    "flange_thickness": "axial thickness of that flange",
    "flange_bolt_circle_diameter": "bolt circle on the flange",
    "flange_bolt_count": "holes on that circle",
    "flange_bolt_hole_diameter": "their diameter",
}


@dataclass(frozen=True)
class PartSizes:
    """The resolved sizes (mm): every field of :class:`PartsSpec` with a value, which were derived, the rule each
    derived size follows, the keys the drive's parts use, and warnings on given sizes that break a rule."""

    values: dict
    derived: tuple
    rules: dict = None
    used: tuple = ()
    notes: tuple = ()

    def __getattr__(self, name):
        try:
            return self.__dict__["values"][name]
        except KeyError:
            raise AttributeError(name) from None


def parse_parts(data) -> PartsSpec:
    """Build a :class:`PartsSpec` from the ``[parts]`` table (a dict, or None when absent)."""
    if data is None:
        return PartsSpec()
    if not isinstance(data, dict):
        raise DesignError("parts", f"must be a table [parts], got {type(data).__name__}")
    known = {f.name: f for f in fields(PartsSpec)}
    kw = {}
    for key, value in data.items():
        if key not in known:
            near = close_matches(key, known)
            hint = f"; did you mean '{near[0]}'?" if near else ""
            raise DesignError(f"parts.{key}", f"unknown key{hint}")
        where = f"parts.{key}"
        if key.endswith("_count"):
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= MAX_BOLTS:
                raise DesignError(where, f"must be a whole number 1..{MAX_BOLTS}, got {show_value(value)}")
        else:
            value = read_float(where, value)
            if not 0 < value <= MAX_PART_MM:
                raise DesignError(where, f"must be a positive number of mm up to {MAX_PART_MM:g}, got {value!r}")
        kw[key] = value
    return PartsSpec(**kw)


def load_parts(path) -> PartsSpec:
    """The ``[parts]`` table of a design file (defaults when it has none)."""
    try:
        data = tomllib.loads(Path(path).read_bytes().decode("utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise InputFileError(f"{path}: cannot read the [parts] table ({e})") from None
    return parse_parts(data.get("parts"))


def _r(x: float, step: float = 0.1) -> float:
    """Round a derived size to a workshop step (0.1 mm)."""
    return max(step, round(round(x / step) * step, 6))


def part_sizes(spec: PartsSpec, drive) -> PartSizes:
    """Every part size, from the ``[parts]`` table or derived from the gear size, checked.

    Defaults (``d`` the flexspline pitch diameter, ``r_in`` its bore radius,
    ``h1`` the rim under its teeth, ``R_rim`` the rigid gear's outer radius):
    cup length = ``generator.cone_length`` or ``0.8 d``; shell =
    ``[material] cup_wall_thickness_mm`` (the wall the models rate) or ``h1``,
    at most ``h1 - 0.05`` (the roots);
    diaphragm = ``1.5 x 0.7 h1`` (rounded to 0.05 mm each), then sized for
    fatigue with the cup's bolt circle by ``wgcad parts`` and ``wgcad rating``
    (wgcad.rating.plate_sizing); hub bore = ``0.5 r_in``; cup bolt circle in
    the middle of the diaphragm's annulus, 8 holes of a third of its width;
    bearing radial thickness ``0.06 x 2 r_in``, width ``0.8 x`` face width;
    plug bore ``0.4 x`` the plug's smallest diameter; flange holes
    ``max(2, 0.025 x 2 R_rim)``, flange ``R_rim + 3`` holes, bolt circle at
    ``R_rim + 1.5`` holes, 12 holes, flange thickness ``0.3 x`` face width.

    Raises
    ------
    DesignError
        A bolt circle that does not fit its annulus (or whose holes overlap),
        a diaphragm thicker than the cup beyond the toothed rim, a shell
        thicker than the rim, a bearing that does not fit the plug (or a
        plug bore larger than the plug).
    """
    v, derived, rules = _derive(spec, drive)
    _check_fits(v, drive)
    notes = _bolt_notes(v, drive, rules)
    ext = drive.external
    used = _used_keys(ext)
    rules = {k: t for k, t in rules.items() if k in derived and k in used}
    return PartSizes(v, tuple(k for k in derived if k in used), rules, used, tuple(notes))


def _derive(spec: PartsSpec, drive) -> tuple[dict, list, dict]:
    """Every size: given in ``[parts]`` or derived (see :func:`part_sizes`); with the derived keys in order and the
    rule each bolt size was chosen by."""
    d = drive.design
    bw = d.drive.face_width
    h1 = d.flexspline.rim_thickness
    ext = drive.external
    given = {f.name: getattr(spec, f.name) for f in fields(PartsSpec)}
    v = dict(given)
    derived = []

    def default(key, value):
        if v[key] is None:
            v[key] = value
            derived.append(key)

    d_pitch = 2.0 * drive.flex.r
    r_in = drive.flex_rim_radius  # flexspline bore (internal deformation) / outer surface (external)
    default("cup_length", d.generator.cone_length if d.generator.cone_length is not None else _r(0.8 * d_pitch))
    # the wall the elastic model and the rating take (docs/design-keys.md: cup_wall_thickness_mm), so the cup exported
    # is the cup rated; a step thinner than the rim at most, which a wall as thick as the rim would reach the roots of
    default("shell_thickness", _r(min(d.material.cup_wall_thickness_mm or h1, h1 - 0.05), 0.05))
    # the plate's starting thickness: 1.5 x the 0.7 h1 of a thin shell (the loaded model's tilting stiffness, 4.2,
    # keeps it), which the fatigue sizing (wgcad.rating.plate_sizing) then checks with the bolt circle
    default("diaphragm_thickness", _r(1.5 * _r(0.7 * h1, 0.05), 0.05))
    default("hub_bore_diameter", _r(0.5 * r_in))

    torque = d.load.rated_torque_nm
    rules = {}
    cup_keys = ("cup_bolt_circle_diameter", "cup_bolt_count", "cup_bolt_hole_diameter")
    if not ext and torque and all(v[k] is None for k in cup_keys):
        # the cup's bolts carry the output torque into the output shaft (wgcad.design.bolting)
        c = choose_bolts(torque, 0.5 * v["hub_bore_diameter"], r_in, "cup")
        for k, val in zip(cup_keys, (_floor(2.0 * c.radius_mm), c.count, c.hole_mm)):
            default(k, val)
            rules[k] = c.text(torque)
    default("cup_bolt_circle_diameter", _r(0.5 * v["hub_bore_diameter"] + r_in))
    default("cup_bolt_count", 8)
    annulus = r_in - 0.5 * v["hub_bore_diameter"]
    default(
        "cup_bolt_hole_diameter",
        _r(min(annulus / 3.0, 0.5 * math.pi * v["cup_bolt_circle_diameter"] / v["cup_bolt_count"])),
    )
    for k in (k for k in cup_keys if k in derived):
        rules.setdefault(
            k,
            "by geometry: in the middle of the diaphragm, holes a third of its width"
            + ("" if torque else " (no [load] rated_torque_nm: not sized for a torque)"),
        )
    default("bearing_thickness", _r(0.06 * 2.0 * (r_in if not ext else drive.r_m)))
    default("bearing_width", _r(0.8 * bw))
    R_rim = drive.rigid_rim_radius
    fl_keys = ("flange_bolt_hole_diameter", "flange_bolt_count", "flange_bolt_circle_diameter", "flange_outer_diameter")
    if torque and all(v[k] is None for k in fl_keys):
        # the rigid gear's bolts carry the reaction torque into the housing (wgcad.design.bolting)
        if not ext:  # a flange around the gear: its rim follows the hole (bolt circle 1.5 holes out, rim 3)
            c = choose_bolts(torque, R_rim, None, "flange", place=lambda hole: R_rim + 1.5 * hole)
            outer = _r(2.0 * (R_rim + 3.0 * c.hole_mm))
        else:  # holes in the body between the bore and the root circle
            c = choose_bolts(torque, R_rim, min(drive.rigid.r_f, drive.rigid.r_a), "flange")
            outer = _r(2.0 * min(drive.rigid.r_f, drive.rigid.r_a))
        for k, val in zip(fl_keys, (c.hole_mm, c.count, _floor(2.0 * c.radius_mm), outer)):
            default(k, val)
            rules[k] = c.text(torque)
    hole = max(2.0, 0.025 * 2.0 * R_rim)
    if ext:  # holes between the bore and the root: ligaments of half a hole either side (wgcad.design.bolting)
        hole = min(hole, 0.45 * (min(drive.rigid.r_f, drive.rigid.r_a) - R_rim))  # 0.45: room for the 0.1 mm rounding
    default("flange_bolt_hole_diameter", _r(hole))
    dh = v["flange_bolt_hole_diameter"]
    if not ext:
        default("flange_outer_diameter", _r(2.0 * (R_rim + 3.0 * dh)))
        default("flange_bolt_circle_diameter", _r(2.0 * (R_rim + 1.5 * dh)))
    else:  # external deformation: the rigid gear has external teeth; holes in its body between bore and root
        default("flange_outer_diameter", _r(2.0 * min(drive.rigid.r_f, drive.rigid.r_a)))
        default("flange_bolt_circle_diameter", _r(R_rim + min(drive.rigid.r_f, drive.rigid.r_a)))
    default("flange_bolt_count", 12)
    geometry = (
        "by geometry: 12 holes of 0.025 x the gear's outer diameter (at least 2 mm"
        + (", at most 0.45 of the body between bore and root" if ext else "")
        + "), on a circle "
        + ("midway between bore and root" if ext else "1.5 holes outside the gear, the flange rim 3 holes out")
        + ("" if torque else " (no [load] rated_torque_nm: not sized for a torque)")
    )
    for k in (k for k in fl_keys if k in derived):
        rules.setdefault(k, geometry)
    default("flange_thickness", _r(min(bw, max(0.3 * bw, 1.5 * dh))))
    return v, derived, rules


def _check_fits(v: dict, drive) -> None:
    """The fit rules of the sizes ``v``, each error naming the key the user sets."""
    d = drive.design
    bw = d.drive.face_width
    h1 = d.flexspline.rim_thickness
    ext = drive.external
    r_in = drive.flex_rim_radius
    R_rim = drive.rigid_rim_radius
    dh = v["flange_bolt_hole_diameter"]
    if v["shell_thickness"] > h1:
        raise DesignError(
            "parts.shell_thickness",
            f"{v['shell_thickness']:g} mm is thicker than the rim under the teeth (flexspline.rim_thickness {h1:g} mm)",
        )
    if not ext:
        room = v["cup_length"] - bw
        if v["cup_length"] <= bw:
            raise DesignError(
                "parts.cup_length", f"{v['cup_length']:g} mm leaves no shell behind the {bw:g} mm toothed rim"
            )
        if v["diaphragm_thickness"] >= room:
            raise DesignError(
                "parts.diaphragm_thickness",
                f"{v['diaphragm_thickness']:g} mm is thicker than the cup behind the toothed rim ({room:g} mm = cup_length - face_width)",
            )
        if v["hub_bore_diameter"] >= 2.0 * r_in:
            raise DesignError(
                "parts.hub_bore_diameter",
                f"{v['hub_bore_diameter']:g} mm leaves no diaphragm inside the cup bore {2 * r_in:.3f} mm",
            )
        _bolts(
            "cup",
            v["cup_bolt_circle_diameter"],
            v["cup_bolt_hole_diameter"],
            v["cup_bolt_count"],
            0.5 * v["hub_bore_diameter"],
            r_in,
            "the hub bore",
            "the cup wall",
        )
    if ext:
        _bolts(
            "flange",
            v["flange_bolt_circle_diameter"],
            dh,
            v["flange_bolt_count"],
            R_rim,
            min(drive.rigid.r_f, drive.rigid.r_a),
            "the bore",
            "the root circle",
        )
    else:
        if v["flange_outer_diameter"] <= 2.0 * R_rim:
            raise DesignError(
                "parts.flange_outer_diameter",
                f"{v['flange_outer_diameter']:g} mm must exceed the rigid gear's outer diameter {2 * R_rim:.3f} mm",
            )
        _bolts(
            "flange",
            v["flange_bolt_circle_diameter"],
            dh,
            v["flange_bolt_count"],
            R_rim,
            0.5 * v["flange_outer_diameter"],
            "the gear body",
            "the flange rim",
        )
    if v["flange_thickness"] > bw:
        raise DesignError(
            "parts.flange_thickness", f"{v['flange_thickness']:g} mm is thicker than the gear (face_width {bw:g} mm)"
        )
    if v["bearing_width"] > (v["cup_length"] if not ext else bw):
        raise DesignError("parts.bearing_width", f"{v['bearing_width']:g} mm is longer than the cup")


def _bolt_notes(v: dict, drive, rules: dict) -> list[str]:
    """Warnings on bolt circles the user gave: a ligament under half a hole, bolts that slip under the design torque."""
    ext = drive.external
    r_in = drive.flex_rim_radius
    R_rim = drive.rigid_rim_radius
    torque = drive.design.load.rated_torque_nm
    notes = []
    # given bolt circles: whether they carry the design torque, and their ligaments (warnings: the user chose them)
    for prefix, lo, hi in (
        ("cup", 0.5 * v["hub_bore_diameter"], r_in),
        ("flange", R_rim, (0.5 * v["flange_outer_diameter"]) if not ext else min(drive.rigid.r_f, drive.rigid.r_a)),
    ):
        if prefix == "cup" and ext:
            continue
        bc, n, hole = (v[f"{prefix}_bolt_{k}"] for k in ("circle_diameter", "count", "hole_diameter"))
        r = 0.5 * bc
        lig = min(r - 0.5 * hole - lo, hi - r - 0.5 * hole)
        if lig < 0.5 * hole - 1e-6:
            notes.append(
                f"{prefix} bolt holes ({hole:g} mm on {bc:g} mm): a ligament of {lig:.2f} mm, less than half a hole"
            )
        sized = rules.get(f"{prefix}_bolt_count", "")[:1].isdigit()  # chosen for the torque above
        fits = [area for name, area, h in METRIC if h <= hole + 1e-9]
        if torque and not sized and fits:
            cap = carry(fits[-1], n, r)
            if cap < SLIP_SAFETY * torque:
                notes.append(
                    f"{prefix} bolts ({n} of the largest metric bolt a {hole:g} mm hole takes) slip at "
                    f"{cap:.0f} N m, less than {SLIP_SAFETY:g} x the design torque {torque:g} N m ({RULE})"
                )
    return notes


def _floor(x: float, step: float = 0.05) -> float:
    """A bolt circle's diameter rounded down to a workshop step: down keeps the outer ligament the rule gave."""
    return round(math.floor(x / step + 1e-9) * step, 6)


def _used_keys(external: bool) -> tuple:
    """The [parts] keys the drive's parts use (external deformation: no cup, no plug bore, no flange)."""
    if not external:
        return tuple(f.name for f in fields(PartsSpec))
    return (
        "bearing_thickness",
        "bearing_width",
        "flange_bolt_circle_diameter",
        "flange_bolt_count",
        "flange_bolt_hole_diameter",
    )


def _bolts(prefix, bc_d, hole_d, count, r_lo, r_hi, inner, outer):
    key = f"parts.{prefix}_bolt_circle_diameter"
    r = 0.5 * bc_d
    if r - 0.5 * hole_d <= r_lo:
        raise DesignError(key, f"{bc_d:g} mm with {hole_d:g} mm holes cuts into {inner} (radius {r_lo:.3f} mm)")
    if r + 0.5 * hole_d >= r_hi:
        raise DesignError(key, f"{bc_d:g} mm with {hole_d:g} mm holes cuts through {outer} (radius {r_hi:.3f} mm)")
    if count > 1 and bc_d * math.sin(math.pi / count) <= hole_d:
        raise DesignError(
            f"parts.{prefix}_bolt_count", f"{count} holes of {hole_d:g} mm overlap on a {bc_d:g} mm bolt circle"
        )


def diaphragm_geometry(drive, t_cup: float) -> tuple[float, float, float, bool]:
    """The cup's diaphragm as a plate: ``(r_i, r_o, h, given)``, mm.

    Clamped at the cup's bolt circle (inside it the output flange holds the plate), joined to the cup wall's
    mid-surface at ``r_o``, ``h`` thick; sizes from the design file's ``[parts]`` (its derived defaults when the
    file has none or the design is in memory). ``given``: the file states the thickness and the bolt circle.
    """
    d = drive.design
    spec = load_parts(d.source) if Path(d.source).is_file() else PartsSpec()
    v = part_sizes(spec, drive)
    r_o = drive.flex_rim_radius + 0.5 * t_cup
    r_i = 0.5 * v.cup_bolt_circle_diameter
    given = spec.diaphragm_thickness is not None and spec.cup_bolt_circle_diameter is not None
    return float(r_i), float(r_o), float(v.diaphragm_thickness), bool(given)
