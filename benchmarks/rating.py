"""Benchmark of ``wgcad rating``: a whole datasheet of D1 (issue 24 asks for under 10 s on the 2-core machine), where its time goes, and the tooth-root FE model's time against its accuracy.

Run from the repository root (not part of the test run):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/rating.py          # best of 3
    .venv/bin/python benchmarks/rating.py --quick                         # one run

Prints a Markdown table and writes output/bench/rating.json. Times are wall
clock, with the ratio to a baseline measured in the same run: one load state
of D1 at 1000 N m from cold (``solve_load``), the unit a datasheet is made of.
The whole process (``wgcad rating`` from a fresh interpreter) is timed too,
as a user waits for it. The FE rows give the tooth-root K_t of D1 cycloidal
(the slowest to converge) at three mesh finenesses against the converged
quadratic reference of the tests (1.919, tests/fe_root_reference.py).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402
from wgcad.elastic import build_model, solve_load  # noqa: E402
from wgcad.rating.datasheet import rate_drive  # noqa: E402
from wgcad.rating.notch import root_concentration  # noqa: E402

D1 = ROOT / "templates" / "d1_involute.toml"
D1_CYCLOIDAL = ROOT / "templates" / "d1_cycloidal.toml"
REFERENCE_KT_CYCLOIDAL = 1.919  # tests/fe_root_reference.py, refine 1..3 (converged within 0.1 %)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    n = 1 if args.quick else 3
    drive = build_drive(load_design(D1))
    model = build_model(drive, 3)
    t_state, _ = best_of(lambda: solve_load(model, 1000.0), n)
    t_sheet, ds = best_of(lambda: rate_drive(build_drive(load_design(D1))), n)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    cmd = [sys.executable, "-m", "wgcad", "rating", str(D1)]
    t_proc, _ = best_of(lambda: subprocess.run(cmd, env=env, capture_output=True, check=True, cwd=ROOT), n)
    cyc = build_drive(load_design(D1_CYCLOIDAL))
    fe = []
    for fin in (1.0, 2.0, 3.0):
        t, rc = best_of(lambda fin=fin: root_concentration(cyc.flex, cyc.flex_rim_radius, fineness=fin), n)
        fe.append(
            {"fineness": fin, "s": t, "kt": rc.kt, "error": rc.kt / REFERENCE_KT_CYCLOIDAL - 1.0, "nodes": rc.nodes}
        )
    rows = [
        ("one load state of D1, 1000 N m, cold (baseline)", t_state, 1.0),
        ("datasheet of D1 (rate_drive)", t_sheet, t_sheet / t_state),
        ("  of it: model, K_t, strength", ds.timing["setup_s"], ds.timing["setup_s"] / t_state),
        ("  of it: levels and limits", ds.timing["limits_s"], ds.timing["limits_s"] / t_state),
        ("wgcad rating D1, whole process", t_proc, t_proc / t_state),
    ]
    print("| what | s | x baseline |\n|---|---|---|")
    for name, t, r in rows:
        print(f"| {name} | {t:.3f} | {r:.1f} |")
    print("\n| root FE of D1 cycloidal, fineness | nodes | s | K_t | error vs reference |\n|---|---|---|---|---|")
    for f in fe:
        print(f"| {f['fineness']:g} | {f['nodes']} | {f['s']:.3f} | {f['kt']:.4f} | {100 * f['error']:+.1f} % |")
    out = ROOT / "output" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    doc = {
        "rows": [{"what": a, "s": b, "ratio": c} for a, b, c in rows],
        "root_fe": fe,
        "rated_torque_nm": ds.rated_torque_nm,
    }
    (out / "rating.json").write_text(json.dumps(doc, indent=2))


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"\n({time.perf_counter() - t0:.1f} s in all)")
