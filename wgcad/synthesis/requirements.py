"""Requirements files (``wgcad design REQ``): what a drive must do, which design keys the search may choose, and in
what ranges (docs/models.md 14).

A requirements file names a base design (every key the search leaves alone is that design's) and says::

    [requirements]
    name = "D1-sized drive, ratio 100"
    base = "../d1_involute.toml"      # relative to this file
    ratio = 100.0                     # z_flex / (z_rigid - z_flex) (rigid gear fixed), exactly
    rated_torque_nm = 300.0           # fatigue, yield and bearing life hold at it (wgcad rating)
    peak_torque_nm = 800.0            # the entry gap stays open, no ratcheting, the bearing's static limit
    max_outside_diameter_mm = 200.0   # the rigid gear's body
    max_length_mm = 170.0             # the flexspline's axial length (a cup: open end to diaphragm)
    lost_motion_arcmin = [0.5, 3.0]   # the datasheet's lost motion at +-4 % of the rated torque
    max_backlash_arcmin = 3.0         # no-load audit
    min_clearance_um = 0.0            # no-load audit: no interference
    entry_gap_closes_below_nm = 3000  # the loaded entry gap closes below this torque (a source's observation)
    min_efficiency = 0.7              # efficiency at the rated torque and [load] input_speed_rpm (wgcad rating)
    cam_offset_um = 40.0              # the cam offset the drive is rated with (default the base's [load])
    objective = "rated_torque"        # what ranks the feasible drives (one, or two for a Pareto front)
    trials = 40
    seed = 1

    [free]                            # "table.key" = [low, high]; integers: a whole-number range
    "generator.w0_coef" = [0.90, 1.05]
    "flexspline.thinning" = [0.0, 0.06]

Bad input is a :class:`~wgcad.errors.DesignError` naming ``requirements.<key>`` or ``free.<table.key>``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

from ..design.files import MAX_DESIGN_BYTES, load_design, parse_toml, read_design_text
from ..design.schema import Design
from ..errors import DesignError
from ..sweep.spec import parse_spec
from ..userfiles import read_user_text

__all__ = ["FreeKey", "Requirements", "OBJECTIVES", "load_requirements", "parse_requirements"]

#: objectives a search can rank by: name -> (sense, meaning). "max": larger is better.
OBJECTIVES = {
    "rated_torque": ("max", "rated torque, N m (wgcad rating: the smallest limit of every criterion)"),
    "stiffness": ("max", "torsional stiffness K3 above T2, N m/rad (wgcad rating's three-segment fit)"),
    "outside_diameter": ("min", "the rigid gear's body diameter, mm"),
    "backlash": ("min", "no-load backlash, arcmin (wgcad audit)"),
    "min_clearance": ("max", "the no-load audit's smallest clearance, um"),
    "efficiency": (
        "max",
        "efficiency at the rated torque and [load] input_speed_rpm (wgcad rating, docs/models.md 10.8)",
    ),
}

_KEYS = {
    "name": str,
    "base": str,
    "ratio": float,
    "rated_torque_nm": float,
    "peak_torque_nm": float,
    "max_outside_diameter_mm": float,
    "max_backlash_arcmin": float,
    "max_length_mm": float,
    "lost_motion_arcmin": list,
    "min_clearance_um": float,
    "entry_gap_closes_below_nm": float,
    "min_efficiency": float,
    "cam_offset_um": float,
    "ke_max_arcsec": float,
    "ke_yield_min": float,
    "ke_samples": int,
    "objective": (str, list),
    "trials": int,
    "seed": int,
}


@dataclass(frozen=True, slots=True)
class FreeKey:
    """A design key the search chooses: ``table.key`` in ``[low, high]`` (``integer``: whole numbers)."""

    table: str
    key: str
    low: float
    high: float
    integer: bool

    @property
    def name(self) -> str:
        return f"{self.table}.{self.key}"


@dataclass(frozen=True, slots=True)
class Requirements:
    """A parsed requirements file (lengths mm, torques N m; None: not required)."""

    name: str
    base: Path
    free: tuple
    objectives: tuple
    ratio: float | None = None
    rated_torque_nm: float | None = None
    peak_torque_nm: float | None = None
    max_outside_diameter_mm: float | None = None
    max_backlash_arcmin: float | None = None
    #: the flexspline's axial length (a cup: generator.cone_length, open end to diaphragm; a ring: the face width)
    max_length_mm: float | None = None
    #: ``(low, high)``: the datasheet's lost motion at +-4 % of the rated torque, arcmin
    lost_motion_arcmin: tuple | None = None
    min_clearance_um: float | None = 0.0
    entry_gap_closes_below_nm: float | None = None
    #: the datasheet's efficiency at the rated torque and input speed must reach this share
    min_efficiency: float | None = None
    cam_offset_um: float | None = None
    #: the KE budget under tolerances: the largest KE (peak to peak over a flexspline turn, arcsec) that a share
    #: ``ke_yield_min`` of ``ke_samples`` drives drawn from ``tolerances`` may not exceed
    ke_max_arcsec: float | None = None
    ke_yield_min: float = 0.99
    ke_samples: int = 40
    #: ``[tolerances.TABLE.KEY]`` as a sweep spec's ``[parameters...]`` (distributions of the imperfections)
    tolerances: dict | None = None
    #: the base design as TOML data (a candidate's KE sweep starts from it)
    base_data: dict | None = None
    trials: int = 40
    seed: int = 0
    source: str = "<memory>"

    @property
    def needs_rating(self) -> bool:
        """Whether a candidate must be rated (the costly stage: the elastic model at every torque it solves)."""
        return (
            self.rated_torque_nm is not None
            or self.peak_torque_nm is not None
            or self.entry_gap_closes_below_nm is not None
            or self.lost_motion_arcmin is not None
            or self.min_efficiency is not None
            or any(o in ("rated_torque", "stiffness", "efficiency") for o in self.objectives)
        )


def _number(where: str, value, kind) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DesignError(where, f"must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise DesignError(where, f"must be finite, got {value!r}")
    if kind is int and v != int(v):
        raise DesignError(where, f"must be a whole number, got {value!r}")
    return v


def _free_keys(data, base: Design) -> tuple:
    if not isinstance(data, dict) or not data:
        raise DesignError("free", 'give at least one design key to choose, as "table.key" = [low, high]')
    out = []
    for name, rng in data.items():
        where = f"free.{name}"
        table, _, key = name.partition(".")
        spec = getattr(base, table, None)
        names = {f.name: f for f in fields(spec)} if spec is not None and hasattr(spec, "__dataclass_fields__") else {}
        if key not in names:
            raise DesignError(where, 'is not a key of the design ("table.key", e.g. "generator.w0_coef")')
        current = getattr(spec, key)
        if isinstance(current, (bool, str)) or (current is not None and not isinstance(current, (int, float))):
            raise DesignError(where, "must be a numeric key of the design (the search chooses numbers)")
        if not (isinstance(rng, list) and len(rng) == 2):
            raise DesignError(where, f"must be [low, high], got {rng!r}")
        integer = all(isinstance(v, int) and not isinstance(v, bool) for v in rng)
        lo, hi = (_number(where, v, int if integer else float) for v in rng)
        if not lo < hi:
            raise DesignError(where, f"low {lo:g} must be below high {hi:g}")
        if integer and not isinstance(current, int):
            raise DesignError(where, "is a real-valued key: give the range as real numbers (e.g. [1.0, 2.0])")
        if not integer and isinstance(current, int):
            raise DesignError(where, "is a whole-number key: give the range as whole numbers (e.g. [190, 210])")
        out.append(FreeKey(table, key, lo, hi, integer))
    return tuple(out)


def _ke_budget(req: dict, tolerances, base_data: dict, base_path: Path) -> dict:
    """``ke_max_arcsec``, ``ke_yield_min``, ``ke_samples`` and the ``[tolerances]`` they are drawn from, checked (the
    tolerances as a sweep spec's parameters would be)."""
    if "ke_max_arcsec" not in req:
        for k in ("ke_yield_min", "ke_samples"):
            if k in req:
                raise DesignError(f"requirements.{k}", "is used only with ke_max_arcsec (the KE budget)")
        if tolerances is not None:
            raise DesignError("tolerances", "is used only with requirements.ke_max_arcsec (the KE budget)")
        return {}
    ke_max = _number("requirements.ke_max_arcsec", req["ke_max_arcsec"], float)
    if not 0 < ke_max <= 3600:
        raise DesignError("requirements.ke_max_arcsec", f"must be in (0, 3600] arcsec, got {ke_max:g}")
    y = _number("requirements.ke_yield_min", req.get("ke_yield_min", 0.99), float)
    if not 0 < y <= 1:
        raise DesignError("requirements.ke_yield_min", f"must be a share in (0, 1], got {y:g}")
    n = int(_number("requirements.ke_samples", req.get("ke_samples", 40), int))
    if not 4 <= n <= 10000:
        raise DesignError("requirements.ke_samples", f"must be in [4, 10000], got {n}")
    if not isinstance(tolerances, dict) or not tolerances:
        raise DesignError("tolerances", "the KE budget needs the tolerances its drives are drawn from")
    # checked as the sweep checks its parameters; its messages name [parameters...], this file [tolerances...]
    try:
        ke_spec(tolerances, base_data, n, 0, ke_max, str(base_path))
    except DesignError as e:
        field = e.field.replace("parameters", "tolerances", 1) if e.field.startswith("parameters") else e.field
        raise DesignError(field, e.rule) from None
    return {"ke_max_arcsec": ke_max, "ke_yield_min": y, "ke_samples": n, "tolerances": tolerances}


def ke_spec(tolerances: dict, design_data: dict, samples: int, seed: int, ke_max: float, source: str):
    """The sweep spec of a candidate's KE budget: ``samples`` drives drawn from ``tolerances``, KE recorded."""
    data = {
        "sweep": {"name": "KE budget", "design": source, "samples": samples, "seed": seed},
        "figures": {"record": ["ke_pp_arcsec"]},
        "parameters": tolerances,
        "limits": {"ke_pp_arcsec": {"max": ke_max}},
    }
    return parse_spec(data, source=source, design_data=design_data)


def parse_requirements(data: dict, path: Path) -> Requirements:
    """Check a requirements file's tables (see the module docstring) and load its base design."""
    unknown = set(data) - {"requirements", "free", "tolerances"}
    if unknown:
        raise DesignError(
            sorted(unknown)[0], "unknown table (a requirements file has [requirements], [free] and [tolerances])"
        )
    req = data.get("requirements")
    if not isinstance(req, dict):
        raise DesignError("requirements", "the table is missing")
    for k in req:
        if k not in _KEYS:
            raise DesignError(f"requirements.{k}", f"unknown key (known: {', '.join(sorted(_KEYS))})")
    if "base" not in req or not isinstance(req["base"], str):
        raise DesignError("requirements.base", "the design file the search starts from (a path relative to this file)")
    base_path = (path.parent / req["base"]).resolve()
    base = load_design(base_path)

    base_data = parse_toml(read_design_text(base_path), base_path, "design file")
    vals = {}
    for k in (
        "ratio",
        "rated_torque_nm",
        "peak_torque_nm",
        "max_outside_diameter_mm",
        "max_backlash_arcmin",
        "max_length_mm",
        "entry_gap_closes_below_nm",
    ):
        if k in req:
            v = _number(f"requirements.{k}", req[k], float)
            if not v > 0:
                raise DesignError(f"requirements.{k}", f"must be > 0, got {v:g}")
            vals[k] = v
    if "min_efficiency" in req:
        v = _number("requirements.min_efficiency", req["min_efficiency"], float)
        if not 0 < v < 1:
            raise DesignError("requirements.min_efficiency", f"must be a share in (0, 1), got {v:g}")
        vals["min_efficiency"] = v
    if "min_clearance_um" in req:
        vals["min_clearance_um"] = _number("requirements.min_clearance_um", req["min_clearance_um"], float)
    if "lost_motion_arcmin" in req:
        lm = req["lost_motion_arcmin"]
        if not (isinstance(lm, list) and len(lm) == 2):
            raise DesignError("requirements.lost_motion_arcmin", f"must be [low, high] arcmin, got {lm!r}")
        lo, hi = (_number("requirements.lost_motion_arcmin", v, float) for v in lm)
        if not 0 <= lo < hi:
            raise DesignError("requirements.lost_motion_arcmin", f"must be 0 <= low < high, got [{lo:g}, {hi:g}]")
        vals["lost_motion_arcmin"] = (lo, hi)
    ke = _ke_budget(req, data.get("tolerances"), base_data, base_path)
    vals.update(ke)
    if "cam_offset_um" in req:
        v = _number("requirements.cam_offset_um", req["cam_offset_um"], float)
        if not 0 <= v <= 1000:
            raise DesignError("requirements.cam_offset_um", f"must be in [0, 1000] um, got {v:g}")
        vals["cam_offset_um"] = v
    obj = req.get("objective", "rated_torque")
    objectives = tuple(obj) if isinstance(obj, list) else (obj,)
    if (
        not 1 <= len(objectives) <= 2
        or any(o not in OBJECTIVES for o in objectives)
        or len(set(objectives)) != len(objectives)
    ):
        raise DesignError(
            "requirements.objective", f"one or two of {', '.join(OBJECTIVES)} (two: a Pareto front), got {obj!r}"
        )
    trials = int(_number("requirements.trials", req.get("trials", 40), int))
    if not 1 <= trials <= 10000:
        raise DesignError("requirements.trials", f"must be in [1, 10000], got {trials}")
    seed = int(_number("requirements.seed", req.get("seed", 0), int))
    name = req.get("name", base.drive.name)
    if not isinstance(name, str) or not 1 <= len(name) <= 200:
        raise DesignError("requirements.name", "must be 1 to 200 characters")
    return Requirements(
        name=name,
        base=base_path,
        free=_free_keys(data.get("free"), base),
        objectives=objectives,
        trials=trials,
        seed=seed,
        source=str(path),
        base_data=base_data,
        **vals,
    )


def load_requirements(path) -> Requirements:
    """Read and check a requirements file (regular file, size-limited like a design file)."""
    path = Path(path)
    text = read_user_text(path, "requirements file", MAX_DESIGN_BYTES, "TOML")
    return parse_requirements(parse_toml(text, path, "requirements file"), path)
