"""Benchmark of the elastic contact model on D1 (200 teeth, 24 balls, 3 sections): one load state, a 13-level sweep, time split.

Run from the repository root (not part of the test run):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/elastic.py   # states best of 5, sweeps best of 3
    .venv/bin/python benchmarks/elastic.py --quick    # one state only

Prints a Markdown table and writes output/bench/elastic.json. Times are
wall-clock on this machine, with the ratio to a baseline measured in the same
run: the exact 2D clearance (wgcad.clearance, polygons, both neighbours) of
every D1 tooth near engagement in the three sections at no load, the geometric
work a full re-linearisation pass repeated before the tables. The acceptance figures of issue 9 are
one state < 50 ms and a 13-level sweep < 1 s on the 2-core machine.

The same 13-level sweep of D1 cycloidal (its states end on a contact that
opens and closes on alternate passes, settled by relaxation) is timed too.

Where the time goes: ``geometry`` is the exact contact geometry of the tooth
pairs (clearance engine, poses, the pair bookkeeping), ``solver`` the
compliance columns and the contact QP; a sweep adds the entry gaps and
summaries of every level (``summary``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

from wgcad.clearance.engine import clearance_at_poses  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402
from wgcad.elastic import build_model, solve_load  # noqa: E402
from wgcad.elastic.sweep import torque_sweep  # noqa: E402
from wgcad.placement import tooth_pose  # noqa: E402

D1 = ROOT / "templates" / "d1_involute.toml"
D1_CYCLOIDAL = ROOT / "templates" / "d1_cycloidal.toml"
OUT = ROOT / "output" / "bench"


def cpu_best_of(fn, n):
    """Fastest wall time of ``n`` runs, the process CPU time of that run and its result.

    With the machine shared (load average above its 2 cores) wall time
    counts the waits for a core; the CPU time of this single-threaded code
    (run with OPENBLAS_NUM_THREADS=1) is what an idle machine would take.
    """
    best = (float("inf"), 0.0, None)
    for _ in range(n):
        t, c = time.perf_counter(), time.process_time()
        val = fn()
        best = min(best, (time.perf_counter() - t, time.process_time() - c, val), key=lambda x: x[0])
    return best


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    drive = build_drive(load_design(D1))
    t_model, model = best_of(lambda: build_model(drive, 3), 3)
    z_g = drive.design.drive.z_flex
    phi = 2 * np.pi * np.arange(z_g) / z_g
    near = np.cos(2 * phi) > 0.2

    def baseline():
        for i in range(3):
            rot, shift = tooth_pose(model.section_law(i), phi, drive.r_m)
            clearance_at_poses(model.scene, rot[near], shift[near], third=False)

    t_base, _ = best_of(baseline, 5)
    # the first state of a fresh model also measures the nominal tooth pairs (kept in model.cache)
    t_first, c_first, _ = cpu_best_of(lambda: solve_load(build_model(drive, 3), 1500.0), 1 if args.quick else 3)
    rows = [
        ("build the model (ring tables, bearing, scene)", t_model, None, t_model / t_base),
        ("baseline: engine clearance of the engaging teeth, 3 sections, no load", t_base, None, 1.0),
        ("first load state of a fresh model, 1500 N m (incl. its nominal pairs)", t_first, c_first, t_first / t_base),
    ]
    res = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "load_average": os.getloadavg(),
        "baseline_s": t_base,
        "model_s": t_model,
        "first_state_s": t_first,
        "states": {},
    }
    for T in (1500.0,) if args.quick else (0.0, 1500.0, 3000.0):
        t_state, c_state, st = cpu_best_of(lambda: solve_load(model, T), 1 if args.quick else 5)
        r = st.residuals
        rows += [
            (f"one load state, {T:.0f} N m ({r['iterations']} passes)", t_state, c_state, t_state / t_base),
            ("  of which contact geometry", st.timing["geometry"], None, None),
            ("  of which compliance and contact solver", st.timing["solver"], None, None),
        ]
        res["states"][f"{T:g}"] = {
            "s": t_state,
            "cpu_s": c_state,
            "passes": r["iterations"],
            "geometry_s": st.timing["geometry"],
            "solver_s": st.timing["solver"],
        }
    if not args.quick:
        for e_um in (0.0, 40.0):
            t_sweep, c_sweep, sw = cpu_best_of(
                lambda: torque_sweep(model, np.arange(0.0, 3000.1, 250.0), cam_offset_um=e_um), 3
            )
            geo = sum(s.timing["geometry"] for s in [lv.state for lv in sw.levels])
            sol = sum(s.timing["solver"] for s in [lv.state for lv in sw.levels])
            passes = sum(s.residuals["iterations"] for s in [lv.state for lv in sw.levels])
            rows += [
                (
                    f"13-level sweep 0:3000:250 N m, e_h = {e_um:g} um, warm-started ({passes} passes)",
                    t_sweep,
                    c_sweep,
                    t_sweep / t_base,
                ),
                ("  of which contact geometry", geo, None, None),
                ("  of which compliance and solver", sol, None, None),
                ("  of which entry gaps and the mounted state", sw.summary_s, None, None),
            ]
            res[f"sweep_{e_um:g}um"] = {
                "s": t_sweep,
                "cpu_s": c_sweep,
                "passes": passes,
                "geometry_s": geo,
                "solver_s": sol,
                "summary_s": sw.summary_s,
            }
    if not args.quick:
        cyc = build_model(build_drive(load_design(D1_CYCLOIDAL)), 3)
        solve_load(cyc, 0.0)  # its nominal pairs, as for the involute model above
        t_sweep, c_sweep, sw = cpu_best_of(lambda: torque_sweep(cyc, np.arange(0.0, 3000.1, 250.0)), 3)
        passes = sum(s.residuals["iterations"] for s in [lv.state for lv in sw.levels])
        rows += [
            (
                f"13-level sweep 0:3000:250 N m, D1 cycloidal, e_h = 0 um ({passes} passes)",
                t_sweep,
                c_sweep,
                t_sweep / t_base,
            )
        ]
        res["sweep_cycloidal_0um"] = {"s": t_sweep, "cpu_s": c_sweep, "passes": passes}
    print(f"machine: {res['machine']}; load average {res['load_average'][0]:.2f}")
    print("| step | wall s | CPU s | ratio to baseline (wall) |\n|---|---|---|---|")
    for name, t, c, r in rows:
        print(f"| {name} | {t:.3f} | {'' if c is None else f'{c:.3f}'} | {'' if r is None else f'{r:.1f}'} |")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "elastic.json").write_text(json.dumps(res, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
