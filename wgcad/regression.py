"""Geometry regression: key figures of a design with per-figure tolerances, recorded and compared."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import DesignError, InputFileError
from .numbers import read_float, read_int
from .userfiles import read_user_text

__all__ = ["FORMAT", "Drift", "baseline_figures", "make_baseline", "load_baseline", "compare", "format_drifts"]

#: version of the baseline file format
FORMAT = 1

# Default tolerances, per figure kind. The computations are deterministic, so
# a drift beyond floating-point noise means the geometry changed:
#: outline areas, relative (1e-9 of ~1e4 mm^2 is 1e-5 mm^2, far below a real change)
AREA_REL_TOL = 1e-9
#: tooth thickness at a radius, mm (closed form: 1 nm)
THICKNESS_TOL_MM = 1e-6
#: clearance figures, um (the engine is exact to 1e-8 um against brute force; 1 nm)
CLEARANCE_TOL_UM = 1e-3
#: backlash, arcmin (1e-4' is 0.006'' of output rotation)
BACKLASH_TOL_ARCMIN = 1e-4


@dataclass(frozen=True)
class Drift:
    """A figure that moved beyond its tolerance (``None`` where a figure is missing or undefined)."""

    key: str
    expected: float | None
    actual: float | None
    tol: float

    def __str__(self) -> str:
        if self.expected is None or self.actual is None:
            return f"  {self.key}: expected {self.expected}, got {self.actual}"
        return (
            f"  {self.key}: expected {self.expected:.9g}, got {self.actual:.9g} "
            f"(diff {self.actual - self.expected:+.3g}, tolerance {self.tol:.3g})"
        )


def baseline_figures(drive, audit_json: dict) -> dict:
    """The figures a baseline records: ``{key: {"value", "tol"}}``."""
    fig = {}
    for name, gear in (("flexspline", drive.flex), ("rigid", drive.rigid)):
        a = gear.area()
        fig[f"{name}.outline_area_mm2"] = {"value": a, "tol": AREA_REL_TOL * abs(a)}
        lo, hi = sorted((gear.r_a, gear.r_f))
        # thickness at the pitch circle (virtual if outside the teeth) and mid-depth
        for label, R in (("pitch", gear.r), ("mid_depth", 0.5 * (lo + hi))):
            fig[f"{name}.tooth_thickness_{label}_mm"] = {
                "value": float(gear.tooth_thickness(R)),
                "tol": THICKNESS_TOL_MM,
            }
        fig[f"{name}.tip_thickness_mm"] = {"value": gear.tip_thickness, "tol": THICKNESS_TOL_MM}
    for key in ("min_clearance_um", "entry_gap_um"):
        fig[key] = {"value": audit_json[key], "tol": CLEARANCE_TOL_UM}
    fig["backlash_arcmin"] = {"value": audit_json["backlash_arcmin"], "tol": BACKLASH_TOL_ARCMIN}
    fig["interference"] = {"value": bool(audit_json["interference"]), "tol": 0}
    return fig


def make_baseline(design_source: str, settings: dict, drive, audit_json: dict) -> dict:
    """A baseline document: design, settings to recompute with, figures with tolerances."""
    return {
        "wgcad_baseline": FORMAT,
        "design": design_source,
        "settings": settings,
        "figures": baseline_figures(drive, audit_json),
    }


#: largest baseline file read, bytes: a baseline holds about a dozen figures (~2 kB)
MAX_BASELINE_BYTES = 1 << 20


def load_baseline(path) -> dict:
    """Read and check a baseline file: its settings and every figure are validated before use.

    Raises
    ------
    InputFileError
        Anything that is not a regular file of at most :data:`MAX_BASELINE_BYTES` holding a wgcad
        baseline: one line naming the part that is wrong.
    """
    p = Path(path)
    text = read_user_text(p, "baseline file", MAX_BASELINE_BYTES, "JSON")
    try:
        doc = json.loads(text, parse_constant=_no_constant)
    except ValueError as e:
        raise InputFileError(f"{p}: not a readable JSON baseline ({e})") from None
    if not isinstance(doc, dict) or doc.get("wgcad_baseline") != FORMAT or not isinstance(doc.get("figures"), dict):
        raise InputFileError(f"{p}: not a wgcad baseline (format {FORMAT})")
    st = doc.get("settings")
    if not isinstance(st, dict):
        raise InputFileError(f"{p}: settings must be a JSON object, got {type(st).__name__}")
    for key in ("step_deg", "sections", "chord_tol_um", "interference_tol_um"):
        if key not in st:
            raise InputFileError(f"{p}: settings.{key} is missing")
        try:
            st[key] = (
                read_int(f"settings.{key}", st[key]) if key == "sections" else read_float(f"settings.{key}", st[key])
            )
        except DesignError as e:
            raise InputFileError(f"{p}: {e}") from None
    for key, fig in doc["figures"].items():
        where = f"figures.{key}"
        if not isinstance(fig, dict) or "value" not in fig:
            raise InputFileError(f"{p}: {where} must be an object with a value")
        v = fig["value"]
        try:
            if v is not None and not isinstance(v, bool):
                fig["value"] = read_float(f"{where}.value", v)
            tol = read_float(f"{where}.tol", fig.get("tol", 0.0))
        except DesignError as e:
            raise InputFileError(f"{p}: {e}") from None
        if tol < 0:
            raise InputFileError(f"{p}: {where}.tol must be >= 0, got {tol:g}")
        fig["tol"] = tol
    return doc


def _no_constant(name: str):
    raise ValueError(f"{name} is not a number a baseline may hold")


def compare(baseline: dict, current: dict) -> list[Drift]:
    """Figures of ``current`` (as from :func:`baseline_figures`) that drifted from ``baseline``'s beyond its tolerances."""
    drifts = []
    for key, ref in baseline["figures"].items():
        exp = ref.get("value")
        tol = float(ref.get("tol", 0.0))
        act = current.get(key, {}).get("value") if key in current else None
        if exp is None or act is None or isinstance(exp, bool) or isinstance(act, bool):
            if exp != act:
                drifts.append(Drift(key, exp, act, tol))
            continue
        if not np.isfinite(act) or abs(float(act) - float(exp)) > tol:
            drifts.append(Drift(key, float(exp), float(act), tol))
    return drifts


def format_drifts(drifts: list[Drift]) -> str:
    """Readable diff: one line per drifted figure."""
    if not drifts:
        return "all figures within their tolerances"
    return f"{len(drifts)} figure(s) drifted beyond tolerance:\n" + "\n".join(str(d) for d in drifts)
