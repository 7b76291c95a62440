"""Helpers for geometry regression tests in pytest: compare a design against a recorded baseline.

Example
-------
>>> from wgcad.testing import assert_matches_baseline          # doctest: +SKIP
>>> assert_matches_baseline("designs/my_drive.toml", "tests/my_drive.baseline.json")  # doctest: +SKIP
"""

from __future__ import annotations

import math

from .regression import baseline_figures, compare, format_drifts, load_baseline, make_baseline
from .report.audit import audit_json
from .services.audit import RunSettings, run_audit

__all__ = ["baseline_drifts", "assert_matches_baseline", "record_baseline", "to_toml"]


def _settings(doc: dict) -> RunSettings:
    s = doc["settings"]
    return RunSettings(
        step_deg=float(s["step_deg"]),
        sections=int(s["sections"]),
        chord_tol_um=float(s["chord_tol_um"]),
        interference_tol_um=float(s["interference_tol_um"]),
    )


def baseline_drifts(design_path, baseline_path) -> list:
    """Recompute the design with the baseline's settings; the figures that drifted (empty when none did)."""
    doc = load_baseline(baseline_path)
    drive, result = run_audit(design_path, _settings(doc))
    return compare(doc, baseline_figures(drive, audit_json(result)))


def assert_matches_baseline(design_path, baseline_path) -> None:
    """Fail with a readable diff when any figure drifted beyond its tolerance."""
    drifts = baseline_drifts(design_path, baseline_path)
    if drifts:
        raise AssertionError(f"{design_path} against {baseline_path}: {format_drifts(drifts)}")


def record_baseline(design_path, settings: RunSettings | None = None) -> dict:
    """A baseline document for a design (write it with ``json.dump``)."""
    rs = settings or RunSettings()
    drive, result = run_audit(design_path, rs)
    keep = {
        k: v for k, v in rs.as_dict().items() if k in ("step_deg", "sections", "chord_tol_um", "interference_tol_um")
    }
    return make_baseline(str(design_path), keep, drive, audit_json(result))


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(data: dict, prefix: str = "") -> str:
    """``data`` (a parsed design or sweep file, or a mutant of one: any value, NaN and infinities included) as
    TOML that ``tomllib`` reads back to the same data; tables nest as ``[a.b]``. For the fuzz tests and
    ``benchmarks/fuzz.py``."""
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            name = f"{prefix}{k}"
            scalars = {kk: vv for kk, vv in v.items() if not isinstance(vv, dict)}
            if scalars or not v:
                lines.append(f"\n[{name}]")
                lines += [f"{kk} = {_toml_value(vv)}" for kk, vv in scalars.items()]
            sub = {kk: vv for kk, vv in v.items() if isinstance(vv, dict)}
            if sub:
                lines.append(to_toml(sub, f"{name}."))
    return "\n".join(lines) + "\n"
