"""Benchmark of the no-load KE (docs/models.md 6.2): D2 over a full flexspline revolution, its error against a 10x finer lattice, the linear model against the direct computation, and the installation-angle optimisation.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/ke.py            # default and 10x finer reference
    .venv/bin/python benchmarks/ke.py --quick    # no 10x reference

Times are wall-clock, best of 3 where cheap; the machine is printed.
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

from wgcad.accuracy import ke as K  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402
from wgcad.placement.imperfect import Imperfections  # noqa: E402

AS = 180.0 / np.pi * 3600.0
D2 = ROOT / "templates" / "d2_imperfect.toml"


def timed(fn, n=1):
    best, val = np.inf, None
    for _ in range(n):
        t = time.perf_counter()
        val = fn()
        best = min(best, time.perf_counter() - t)
    return best, val


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    out = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"
    }
    t_build, drive = timed(lambda: build_drive(load_design(D2)))
    imp = Imperfections.from_spec(drive.design.imperfections)
    out["build_drive_s"] = round(t_build, 3)
    out["load_avg_1_5_15"] = [round(x, 2) for x in os.getloadavg()]
    N = K.DEFAULT_N
    t_tab, tab = timed(lambda: K.contact_table(drive, imp, N), 3)
    t_ke, res = timed(lambda: K.kinematic_error(drive, imp, table=tab), 3)
    out["default"] = {
        "per_mesh": N,
        "samples": len(res.ke),
        "table_s": round(t_tab, 3),
        "ke_s": round(t_ke, 3),
        "total_s": round(t_tab + t_ke, 3),
        "ke_pp_arcsec": round(res.ke_pp * AS, 4),
        "deep_overlap_fraction": round(res.deep_overlap_fraction, 4),
        "engagement": res.engagement,
        "lost_motion_arcsec": [round(res.lost_motion.min() * AS, 3), round(res.lost_motion.max() * AS, 3)],
    }
    print(json.dumps(out, indent=1), flush=True)
    # the linear model against exact poses and a fresh contact search, at the [S4] amplitudes
    rng = np.random.default_rng(1)
    idx = np.sort(rng.choice(len(res.ke), 12, replace=False))
    diffs = []
    t_dir = time.perf_counter()
    for i in idx:
        for side, arr in ((tab.side_w, res.delta_w), (-tab.side_w, res.delta_n)):
            diffs.append((arr[i] - K.closing_direct(drive, imp, res.phi_h[i], side)) * AS)
    t_dir = (time.perf_counter() - t_dir) / (2 * len(idx))
    # the full drive is flagged (deep overlaps at the open end, ke.DEEP_OVERLAP): this is the figure the flag warns of
    out["linear_vs_direct"] = {
        "angles": int(len(idx)),
        "max_abs_arcsec": round(float(np.abs(diffs).max()), 4),
        "median_abs_arcsec": round(float(np.median(np.abs(diffs))), 4),
        "direct_s_per_angle_and_side": round(t_dir, 3),
    }
    print(json.dumps(out["linear_vs_direct"]), flush=True)
    t_opt, (best, best_pp, grid, pp) = timed(lambda: K.optimize_install_angle(tab, imp), 3)
    out["install_angle"] = {
        "optimise_s": round(t_opt, 3),
        "angles_evaluated": 36 + 63 + 21,
        "best_deg": round(float(np.degrees(best)), 3),
        "best_ke_pp_arcsec": round(best_pp * AS, 4),
        "range_arcsec": [round(float(pp.min()) * AS, 4), round(float(pp.max()) * AS, 4)],
    }
    print(json.dumps(out["install_angle"]), flush=True)
    if not args.quick:
        t_tab10, tab10 = timed(lambda: K.contact_table(drive, imp, 10 * N))
        t_ke10, res10 = timed(lambda: K.kinematic_error(drive, imp, table=tab10))
        common = res10.ke[::10][: len(res.ke)]
        out["reference_10x"] = {
            "per_mesh": 10 * N,
            "samples": len(res10.ke),
            "table_s": round(t_tab10, 3),
            "ke_s": round(t_ke10, 3),
            "ke_pp_arcsec": round(res10.ke_pp * AS, 4),
            "ke_pp_error_arcsec": round((res.ke_pp - res10.ke_pp) * AS, 4),
            "max_abs_diff_at_common_angles_arcsec": round(float(np.abs(common - res.ke).max()) * AS, 6),
        }
        print(json.dumps(out["reference_10x"]), flush=True)
    # where the linear model holds: the [S4] amplitudes scaled down (N = 4, centre section, to be quick)
    out["linear_vs_direct_by_scale"] = []
    for scale in (1.0, 0.1, 0.02):
        sc = imp.replace(
            **{k: getattr(imp, k) * scale for k in ("flex_runout", "rigid_runout", "cam_cam", "cam_fixed", "cam_flex")}
        )
        tb = K.contact_table(drive, sc, 4, sections=[None])
        r = K.kinematic_error(drive, sc, table=tb, samples=4 * 202 * 3)
        dd = [
            (arr[i] - K.closing_direct(drive, sc, r.phi_h[i], side, sections=[None])) * AS
            for i in (0, 301, 1001, 2222)
            for side, arr in ((tb.side_w, r.delta_w), (-tb.side_w, r.delta_n))
        ]
        row = {
            "scale": scale,
            "max_abs_arcsec": round(float(np.abs(dd).max()), 5),
            "engagement": r.engagement,
            "deep_overlap_fraction": round(r.deep_overlap_fraction, 4),
        }
        out["linear_vs_direct_by_scale"].append(row)
        print(json.dumps(row), flush=True)
    dest = ROOT / "output" / "bench"
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "ke.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
