"""Benchmark of conjugate teeth (issue 25): the rigid gear conjugate to D1's 200-tooth flexspline (involute,
cycloidal, double arc) and its audit, and the search for the balanced face taper of a coned cup.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/envelope.py          # best of 3
    .venv/bin/python benchmarks/envelope.py --quick  # one run

Prints a Markdown table and writes output/bench/envelope.json. Wall clock, with the ratio to a baseline measured in
the same run: the audit of the design's own rigid gear at the same section and settings (a whole generator turn at
0.5 deg, refined on the exact pieces, which the audit rebuilds from the design at an eighth of the tolerance: with
a conjugate gear that is a second conjugate construction). The conjugate gear is built as a design asks for it
([rigid] flanks = "conjugate"); its flank is one Hermite spline through the exact envelope points.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

from wgcad.clearance import AuditSettings, audit  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    n = 1 if ap.parse_args().quick else 3
    rows, doc = [], {}
    for name in ("d1_involute", "d1_cycloidal", "d1_double_arc"):
        design = load_design(ROOT / "templates" / f"{name}.toml")
        # the baseline: the design's own rigid gear (the double arc's template asks for a conjugate one)
        own_design = dataclasses.replace(
            design, rigid=dataclasses.replace(design.rigid, flanks="form", conjugate_clearance_um=0.0)
        )
        d = build_drive(own_design)
        z = design.generator.generator_z
        st = AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=[z], interference_tol=1e-3, refine=True)
        t_base, own = best_of(lambda d=d, st=st: audit(d, st), n)
        # the conjugate gear as a design asks for it (the engine rebuilds the drive from the design for its finer
        # polygons: a gear swapped into a built drive would be refined against the design's own)
        conj_design = dataclasses.replace(design, rigid=dataclasses.replace(design.rigid, flanks="conjugate"))
        t_env, conj = best_of(lambda cd=conj_design: build_drive(cd), n)
        t_own_build, _ = best_of(lambda des=own_design: build_drive(des), n)
        t_aud, res = best_of(lambda conj=conj, st=st: audit(conj, st), n)
        rows += [
            (f"{name}: audit of the design's rigid gear (baseline)", t_base, 1.0, 1e3 * own.min_clearance),
            (f"{name}: build_drive with its own rigid gear", t_own_build, t_own_build / t_base, None),
            (f"{name}: build_drive with the conjugate rigid gear", t_env, t_env / t_base, None),
            (f"{name}: audit of the conjugate pair", t_aud, t_aud / t_base, 1e3 * res.min_clearance),
        ]
        doc[name] = {"min_clearance_um": 1e3 * res.min_clearance}
    # the spatial modification's search (docs/models.md 13.4): the balanced face taper of D1's conjugate pair,
    # polygon audits of both face ends, then both ends exactly
    from wgcad.report.sections import balanced_taper

    d = build_drive(load_design(ROOT / "templates" / "d1_conjugate.toml"))
    st = AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=np.array([0.0, 30.0]), refine=True)
    t_bal, bal = best_of(lambda: balanced_taper(d, st), n)
    rows.append(
        (
            "d1_conjugate: balanced face taper (search, exact check; x the d1_involute baseline)",
            t_bal,
            t_bal / rows[0][1],
            None,
        )
    )
    doc["balanced_taper"] = bal
    print("| what | s | x baseline | smallest clearance, um |\n|---|---|---|---|")
    for what, t, r, c in rows:
        print(f"| {what} | {t:.3f} | {r:.2f} | {'-' if c is None else f'{c:.6f}'} |")
    out = ROOT / "output" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    doc["rows"] = [{"what": a, "s": b, "ratio": c} for a, b, c, _ in rows]
    (out / "envelope.json").write_text(json.dumps(doc, indent=2))


if __name__ == "__main__":
    main()
