"""Benchmark of conjugate teeth (issue 25, 37): the rigid gear conjugate to D1's 200-tooth flexspline (involute,
cycloidal, double arc), its build and its audit, and the search for the balanced face taper of a coned cup.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/envelope.py          # median of 3
    .venv/bin/python benchmarks/envelope.py --quick  # one run

Prints a Markdown table and writes output/bench/envelope.json: for each step the median wall clock and CPU
time of its runs, and the ratio of the wall clock to a baseline measured in the same run, the audit of the
design's own rigid gear at the same section and settings (a whole generator turn at 0.5 deg, refined on the
exact pieces). The conjugate gear is built as a design asks for it ([rigid] flanks = "conjugate"), from scratch
at every run (the process keeps the last few built: drive._CONJUGATES is emptied first); its audit rebuilds the
drive at an eighth of the tolerance for its finer polygons, sampling the same exact pieces (the flank is not
enveloped again).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from wgcad import drive as drive_mod  # noqa: E402
from wgcad.clearance import AuditSettings, audit  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402


def median_of(fn, n: int):
    """Median wall clock and CPU time of ``n`` runs of ``fn()`` (s), and the last run's result."""
    wall, cpu = [], []
    for _ in range(n):
        t, c = time.perf_counter(), time.process_time()
        val = fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return statistics.median(wall), statistics.median(cpu), val


def _fresh_build(design):
    drive_mod._CONJUGATES.clear()  # the envelope itself, not the process's kept gear
    return build_drive(design)


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
        t_base, c_base, own = median_of(lambda d=d, st=st: audit(d, st), n)
        conj_design = dataclasses.replace(design, rigid=dataclasses.replace(design.rigid, flanks="conjugate"))
        t_env, c_env, conj = median_of(lambda cd=conj_design: _fresh_build(cd), n)
        t_own, c_own, _ = median_of(lambda des=own_design: build_drive(des), n)
        t_aud, c_aud, res = median_of(lambda conj=conj, st=st: audit(conj, st), n)
        rows += [
            (f"{name}: audit of the design's rigid gear (baseline)", t_base, c_base, t_base, 1e3 * own.min_clearance),
            (f"{name}: build_drive with its own rigid gear", t_own, c_own, t_base, None),
            (f"{name}: build_drive with the conjugate rigid gear", t_env, c_env, t_base, None),
            (f"{name}: audit of the conjugate pair", t_aud, c_aud, t_base, 1e3 * res.min_clearance),
        ]
        doc[name] = {"min_clearance_um": 1e3 * res.min_clearance, "refined": res.counts.get("refined")}
    # the spatial modification's search (docs/models.md 13.4): the balanced face taper of D1's conjugate pair,
    # polygon audits of both face ends, then both ends exactly
    from wgcad.report.sections import balanced_taper

    d = build_drive(load_design(ROOT / "templates" / "d1_conjugate.toml"))
    st = AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=np.array([0.0, 30.0]), refine=True)
    t_bal, c_bal, bal = median_of(lambda: balanced_taper(d, st), n)
    what = "d1_conjugate: balanced face taper (search, exact check; x the d1_involute baseline)"
    rows.append((what, t_bal, c_bal, rows[0][1], None))
    doc["balanced_taper"] = bal
    print(f"median of {n}")
    print("| what | wall s | CPU s | x baseline (wall) | smallest clearance, um |\n|---|---|---|---|---|")
    for what, t, c, base, cl in rows:
        print(f"| {what} | {t:.3f} | {c:.3f} | {t / base:.2f} | {'-' if cl is None else f'{cl:.6f}'} |")
    out = ROOT / "output" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    doc["runs"] = n
    doc["rows"] = [{"what": a, "s": b, "cpu_s": c, "ratio": b / base} for a, b, c, base, _ in rows]
    (out / "envelope.json").write_text(json.dumps(doc, indent=2))


if __name__ == "__main__":
    main()
