"""Benchmark of the sectored rigid gear (issue 11): time of both height methods, their difference per tooth, sweep-step convergence, audit shortcuts.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/sector.py            # about a minute
    .venv/bin/python benchmarks/sector.py --quick    # fewer repeats, coarser reference

Writes output/bench/sector.json and sector.md. Times are wall-clock best-of-N
on this machine, with ratios to a baseline measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

import wgcad.sector.scene as scene_mod  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive, tooth_spec  # noqa: E402
from wgcad.profiles.sector import TeethByHeight, sector_layout  # noqa: E402
from wgcad.report.sector import sectored_audit_document  # noqa: E402
from wgcad.sector import SectoredScene, closed_form_heights, sectored_audit, simulated_heights  # noqa: E402

OUT = ROOT / "output" / "bench"
D4 = ROOT / "templates" / "d4_sectored.toml"


def setup():
    design = load_design(D4)
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    # a fresh tooth cache per call would time make_gear too; each method gets its own cache below
    return design, drive, lay


def teeth_of(design, drive):
    return TeethByHeight(tooth_spec(design, "rigid"), drive.rigid)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n = 1 if args.quick else 3
    design, drive, lay = setup()
    c_req = 1e-3 * design.sectors.tip_clearance_um
    step = scene_mod.DEFAULT_STEP_DEG
    res: dict = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "design": str(D4.relative_to(ROOT)),
        "step_deg": step,
        "tip_clearance_um": 1e3 * c_req,
        "repeats": n,
    }

    # 1. time of both methods (each run with an empty tooth cache: the make_gear calls are part of the cost)
    t_cfb, cfb = best_of(lambda: closed_form_heights(drive, lay, teeth_of(design, drive), assign="boundary"), n)
    t_cf, cf = best_of(
        lambda: closed_form_heights(drive, lay, teeth_of(design, drive), assign="register", step_deg=step), n
    )
    t_sim, sim = best_of(lambda: simulated_heights(drive, lay, teeth_of(design, drive), c_req, step_deg=step), n)
    t_sim0, sim0 = best_of(lambda: simulated_heights(drive, lay, teeth_of(design, drive), 0.0, step_deg=step), n)
    res["time_s"] = {
        "closed_form_boundary": t_cfb,
        "closed_form_register": t_cf,
        "simulated": t_sim,
        "simulated_zero_clearance": t_sim0,
        "simulated_over_closed_form_register": t_sim / t_cf,
    }
    res["simulated_counts"] = sim.counts
    cs = lay.coupling_sector_teeth()
    tj = np.nonzero(~lay.coupling & (sim.heights < cf.full - 1e-12))[0]
    res["per_tooth_first_coupling_sector"] = [
        {
            "tooth_in_sector": int(k),
            "from_boundary_deg": round(float(np.rad2deg(lay.delta[i])), 4),
            "closed_form_boundary_um": round(1e3 * float(cfb.heights[i]), 3),
            "closed_form_um": round(1e3 * float(cf.heights[i]), 3),
            "assigned_phi_deg": round(float(np.rad2deg(cf.phi[i])), 3),
            "simulated_um": round(1e3 * float(sim.heights[i]), 3),
            "simulated_0um_um": round(1e3 * float(sim0.heights[i]), 3),
            "sim_minus_cf_um": round(1e3 * float(sim.heights[i] - cf.heights[i]), 3),
            "sim0_minus_cf_um": round(1e3 * float(sim0.heights[i] - cf.heights[i]), 3),
        }
        for k, i in enumerate(cs)
    ]
    res["transmission_joint_teeth"] = [
        {
            "tooth": int(i),
            "closed_form_um": round(1e3 * float(cf.heights[i]), 3),
            "simulated_um": round(1e3 * float(sim.heights[i]), 3),
        }
        for i in tj
    ]
    d = 1e3 * (sim.heights - cf.heights)[cs]
    d0 = 1e3 * (sim0.heights - cf.heights)[cs]
    res["difference_um"] = {
        "sim_minus_cf": [float(d.min()), float(d.max())],
        "sim0_minus_cf": [float(d0.min()), float(d0.max())],
    }

    # 2. sweep-step convergence against a fine reference
    ref_step = 0.05 if args.quick else 0.02
    ref_cf = closed_form_heights(drive, lay, teeth_of(design, drive), step_deg=ref_step).heights
    ref_sim = simulated_heights(drive, lay, teeth_of(design, drive), c_req, step_deg=ref_step).heights
    conv = []
    for s in (1.0, 0.5, 0.25, 0.1, 0.05):
        if s <= ref_step:
            continue
        tc, hc = best_of(lambda: closed_form_heights(drive, lay, teeth_of(design, drive), step_deg=s).heights, 1)
        ts, hs = best_of(lambda: simulated_heights(drive, lay, teeth_of(design, drive), c_req, step_deg=s).heights, 1)
        conv.append(
            {
                "step_deg": s,
                "closed_form_max_err_um": round(1e3 * float(np.abs(hc - ref_cf).max()), 3),
                "simulated_max_err_um": round(1e3 * float(np.abs(hs - ref_sim).max()), 3),
                "closed_form_s": round(tc, 3),
                "simulated_s": round(ts, 3),
            }
        )
    res["step_convergence"] = {"reference_step_deg": ref_step, "rows": conv}

    # 3. audit: full vs built heights, and the shortcuts (half turn for identical waves; third tooth only where reachable)
    teeth = teeth_of(design, drive)
    full = np.full(lay.n_teeth, teeth.height)
    t_full, a_full = best_of(lambda: sectored_audit(SectoredScene(drive, lay, teeth, full), step), n)
    t_built, a_built = best_of(lambda: sectored_audit(SectoredScene(drive, lay, teeth, sim.heights), step), n)
    res["audit"] = {
        "full_height": {
            "s": t_full,
            **{
                k: v
                for k, v in sectored_audit_document(a_full).items()
                if k in ("tip_to_tip", "tip_to_tip_teeth", "min_tip_clearance_um", "min_flank_clearance_um", "counts")
            },
        },
        "simulated_heights": {
            "s": t_built,
            **{
                k: v
                for k, v in sectored_audit_document(a_built).items()
                if k in ("tip_to_tip", "tip_to_tip_teeth", "min_tip_clearance_um", "min_flank_clearance_um", "counts")
            },
        },
    }
    scene = SectoredScene(drive, lay, teeth, sim.heights)

    def whole_turn():
        # no identical-waves shortcut: a whole turn of generator angles
        ang = np.concatenate([scene_mod.sweep_angles(step), scene_mod.sweep_angles(step) + np.pi])
        p = scene.pairs(ang)
        return scene.clearance(p), p

    t_whole, (c_whole, p_whole) = best_of(whole_turn, 1)
    t_half, (c_half, p_half) = best_of(
        lambda: (lambda p: (scene.clearance(p), p))(scene.pairs(scene_mod.sweep_angles(step))), 1
    )
    saved = scene_mod.THIRD_TOOTH_WITHIN
    scene_mod.THIRD_TOOTH_WITHIN = 1.0
    t_all3, (c_all3, p_all3) = best_of(
        lambda: (lambda p: (scene.clearance(p), p))(scene.pairs(scene_mod.sweep_angles(step))), 1
    )
    scene_mod.THIRD_TOOTH_WITHIN = saved
    res["shortcuts"] = {
        "identical_waves": {
            "half_turn_s": t_half,
            "whole_turn_s": t_whole,
            "speedup": t_whole / t_half,
            "min_clearance_difference_um": 1e3 * abs(float(c_whole.min()) - float(c_half.min())),
        },
        "third_tooth_when_reachable": {
            "pairs": int(len(p_half)),
            "pairs_all_third": int(len(p_all3)),
            "s": t_half,
            "s_all_third": t_all3,
            "speedup": t_all3 / t_half,
            "min_clearance_difference_um": 1e3 * abs(float(c_all3.min()) - float(c_half.min())),
        },
    }
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "sector.json").write_text(json.dumps(res, indent=2) + "\n")
    md = [
        f"# Sectored rigid gear benchmark ({res['machine']})",
        "",
        f"D4 sectored, sweep {step} deg over half a turn, tip clearance {1e3 * c_req:g} um, best of {n}.",
        "",
        "| method | time, s |",
        "|---|---|",
    ]
    for k, v in res["time_s"].items():
        md.append(f"| {k} | {v:.3f} |")
    md += [
        "",
        "| tooth | from boundary, deg | closed form (boundary), um | closed form, um | phi_i, deg | simulated, um | sim - cf, um | sim(0 um) - cf, um |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in res["per_tooth_first_coupling_sector"]:
        md.append(
            f"| {r['tooth_in_sector']} | {r['from_boundary_deg']} | {r['closed_form_boundary_um']} | {r['closed_form_um']} | {r['assigned_phi_deg']} | "
            f"{r['simulated_um']} | {r['sim_minus_cf_um']} | {r['sim0_minus_cf_um']} |"
        )
    md += [
        "",
        "| step, deg | closed form max err, um | simulated max err, um | closed form, s | simulated, s |",
        "|---|---|---|---|---|",
    ]
    for r in conv:
        md.append(
            f"| {r['step_deg']} | {r['closed_form_max_err_um']} | {r['simulated_max_err_um']} | {r['closed_form_s']} | {r['simulated_s']} |"
        )
    (OUT / "sector.md").write_text("\n".join(md) + "\n")
    print(
        json.dumps(
            {
                k: res[k]
                for k in (
                    "time_s",
                    "difference_um",
                    "transmission_joint_teeth",
                    "step_convergence",
                    "audit",
                    "shortcuts",
                )
            },
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
