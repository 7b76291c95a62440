"""What moves [S1]'s figures under load: D1's involute closing torque and cycloidal entry-gap range against each
reading the source leaves open (docs/models.md 9, "D1 under load: the readings").

Run from the repository root (not part of the test run):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/loaded_sensitivity.py          # every reading
    .venv/bin/python benchmarks/loaded_sensitivity.py --only hertz,planar              # some

For each reading one key of templates/d1_involute.toml and templates/d1_cycloidal.toml changes (the row says
which); the load audit's torque sweep (0 to 3000 N m in steps of 250, the sections of the audit) gives

* involute: the smallest entry gap Delta at no load and the torque where it closes (crosses zero, interpolated
  between the levels; "> 3000" if it does not);
* cycloidal: Delta at no load and at 3000 N m, and their difference (the range [S1] plots).

Prints a Markdown table and writes output/bench/loaded_sensitivity.json.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from wgcad.design import load_design, with_changes  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402
from wgcad.elastic import build_model  # noqa: E402
from wgcad.elastic.sweep import torque_sweep  # noqa: E402

OUT = ROOT / "output" / "bench"
TORQUES = [250.0 * k for k in range(13)]

#: the readings: (name, what [S1] leaves open, the tables changed)
READINGS = [
    ("template", "the templates as they stand", {}),
    ("hertz", "tooth pair: Hertz alone, as [S1] writes lambda(Q)", {"load": {"tooth_compliance": "hertz"}}),
    ("no_fit_gap", "the 26 um between outer ring and flexspline read as 0", {"bearing": {"fit_clearance_um": 0.0}}),
    ("one_gap", "the two 26 um read as one gap of 26 um", {"bearing": {"internal_clearance_um": 0.0}}),
    (
        "rim_h1",
        "rim's equivalent thickness = h1 (teeth add nothing)",
        {"material": {"rim_equivalent_thickness_mm": 1.4}},
    ),
    (
        "rim_h1_half",
        "rim's equivalent thickness = h1 + half the tooth height",
        {"material": {"rim_equivalent_thickness_mm": 2.0}},
    ),
    ("planar", "planar rim (one rigid motion, the cup's twist in series)", {"supports": {"rim": "planar"}}),
    ("soft_diaphragm", "a thin wide diaphragm: tilt 1e4 N m/rad", {"supports": {"diaphragm_tilt_nm_per_rad": 1e4}}),
    ("cam_1e4", "cam on a compliant shaft: 1e4 N/mm", {"supports": {"cam_radial_n_per_mm": 1e4}}),
    ("cam_floating", "cam floating (Oldham coupling)", {"supports": {"cam_radial_n_per_mm": 0.0}}),
    (
        "rigid_1e5",
        "rigid gear's seat 1e5 N/mm, 1e6 N m/rad",
        {"supports": {"rigid_gear_radial_n_per_mm": 1e5, "rigid_gear_tilt_nm_per_rad": 1e6}},
    ),
]


def _sweep(design, sections: int = 3):
    """Delta at every level; NaN from the first level the model does not converge at (said in the row)."""
    from wgcad.elastic.solve import ContactSolveError

    model = build_model(build_drive(design), sections)
    try:
        sw = torque_sweep(model, TORQUES)
    except ContactSolveError as e:
        print(f"  no convergence: {e}", flush=True)
        return np.full(len(TORQUES), np.nan)
    return np.array([lv.entry_gap for lv in sw.levels])


def _closing(gaps) -> float | None:
    """The torque where Delta crosses zero, interpolated between the levels (None if it stays open)."""
    for k in range(1, len(gaps)):
        if gaps[k] < 0.0 <= gaps[k - 1]:
            t = gaps[k - 1] / (gaps[k - 1] - gaps[k])
            return TORQUES[k - 1] + t * (TORQUES[k] - TORQUES[k - 1])
    return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated reading names")
    args = ap.parse_args(argv)
    names = None if not args.only else set(args.only.split(","))
    inv = load_design(ROOT / "templates" / "d1_involute.toml")
    cyc = load_design(ROOT / "templates" / "d1_cycloidal.toml")
    rows = []
    for name, what, change in READINGS:
        if names and name not in names:
            continue
        t0 = time.perf_counter()
        gi = _sweep(with_changes(inv, **change) if change else inv)
        gc = _sweep(with_changes(cyc, **change) if change else cyc)
        close = _closing(gi)
        row = {
            "reading": name,
            "what": what,
            "involute_delta0_um": round(1e3 * gi[0], 2),
            "involute_closing_nm": None if close is None else round(close, 0),
            "cycloidal_delta0_um": round(1e3 * gc[0], 2),
            "cycloidal_delta3000_um": round(1e3 * gc[-1], 2),
            "cycloidal_range_um": round(1e3 * (gc[0] - gc[-1]), 2),
            "seconds": round(time.perf_counter() - t0, 1),
        }
        rows.append(row)
        print(json.dumps(row), flush=True)
    print()
    print("| reading | involute Delta(0) um | closes at N m | cycloidal Delta 0 -> 3000 N m um | range um |")
    print("|---|---|---|---|---|")
    for r in rows:
        c = "> 3000" if r["involute_closing_nm"] is None else f"{r['involute_closing_nm']:.0f}"
        print(
            f"| {r['what']} | {r['involute_delta0_um']:.1f} | {c} | {r['cycloidal_delta0_um']:.1f} -> "
            f"{r['cycloidal_delta3000_um']:.1f} | {r['cycloidal_range_um']:.1f} |"
        )
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "loaded_sensitivity.json").write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
