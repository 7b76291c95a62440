"""Benchmarks: run time against error for each accuracy knob, shortcuts on/off, and the audit's acceptance figures.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/run.py            # everything, a few minutes
    .venv/bin/python benchmarks/run.py --quick    # smaller sweeps, no brute force

Writes tables (CSV and Markdown) and one PNG per knob to output/bench/.
Times are wall-clock best-of-N on this machine, quoted with ratios to a
baseline measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from math import pi
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import best_of  # noqa: E402

from wgcad.clearance.engine import AuditSettings, audit, brute_force_min  # noqa: E402
from wgcad.design import load_design  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402

OUT = ROOT / "output" / "bench"
D1 = ROOT / "templates" / "d1_involute.toml"


def machine() -> str:
    return f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"


def audit_of(drive, step_deg, k, **kw):
    n = int(round(360.0 / step_deg))
    angles = np.deg2rad(np.arange(n) * 360.0 / n)
    return audit(drive, AuditSettings(angles=angles, sections=drive.sections(k), **kw))


def peak_memory_mb() -> float:
    """Peak RSS of a fresh process doing only the full-revolution D1 audit."""
    code = (
        f"import resource, sys; sys.path.insert(0, {str(ROOT)!r})\n"
        "from benchmarks.run import audit_of, build_drive, load_design, D1\n"
        "audit_of(build_drive(load_design(D1)), 0.5, 3)\n"
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    return float(r.stdout.strip().splitlines()[-1])


def bench_audit(quick: bool) -> dict:
    """Issue 4 acceptance: full revolution at 0.5 deg and 3 sections vs the brute force; one mesh period; memory."""
    drive = build_drive(load_design(D1))
    t_fast, fast = best_of(lambda: audit_of(drive, 0.5, 3), 3)
    t_poly, poly = best_of(lambda: audit_of(drive, 0.5, 3, refine=False), 3)
    mesh = 360.0 / drive.design.drive.z_rigid
    angles_1p = np.deg2rad(np.arange(0.0, mesh, 0.5))
    t_1p, one = best_of(lambda: audit(drive, AuditSettings(angles=angles_1p, sections=drive.sections(3))), 5)
    t_1pp, _ = best_of(
        lambda: audit(drive, AuditSettings(angles=angles_1p, sections=drive.sections(3), refine=False)), 5
    )
    out = {
        "machine": machine(),
        "full_revolution_s": t_fast,
        "full_revolution_polygon_only_s": t_poly,
        "one_period_polygon_only_s": t_1pp,
        "refined_samples": fast.counts.get("refined", 0),
        "min_clearance_um": 1e3 * fast.min_clearance,
        "min_clearance_polygon_um": 1e3 * poly.min_clearance,
        "samples": fast.counts["samples"],
        "evaluated": fast.counts["evaluated"],
        "one_period_s": t_1p,
        "one_period_angles": len(angles_1p),
        "peak_memory_mb": peak_memory_mb(),
    }
    if not quick:
        n = 720
        angles = np.deg2rad(np.arange(n) * 360.0 / n)
        t0 = time.perf_counter()
        brute = brute_force_min(drive, angles, drive.sections(3))
        out["brute_force_s"] = time.perf_counter() - t0
        out["brute_force_min_um"] = 1e3 * brute
        out["speedup"] = out["brute_force_s"] / t_fast
        out["difference_um"] = abs(1e3 * (brute - fast.min_clearance))
    return out


def bench_shortcuts(quick: bool) -> list[dict]:
    """Each shortcut switched off alone (and all off): time and the change in the result."""
    drive = build_drive(load_design(D1))
    step = 2.0 if quick else 1.0
    t_on, on = best_of(lambda: audit_of(drive, step, 3), 3)
    rows = [
        {
            "shortcut": "all on (baseline)",
            "time_s": t_on,
            "ratio": 1.0,
            "min_clearance_um": 1e3 * on.min_clearance,
            "change_um": 0.0,
        }
    ]
    names = {
        "use_period": "mesh period",
        "use_waves": "identical waves",
        "use_mirror": "mirror symmetry",
        "cull": "radial culling",
        "bound": "branch and bound",
    }
    for key, label in names.items():
        t, r = best_of(lambda: audit_of(drive, step, 3, **{key: False}), 1)
        rows.append(
            {
                "shortcut": f"{label} off",
                "time_s": t,
                "ratio": t / t_on,
                "min_clearance_um": 1e3 * r.min_clearance,
                "change_um": 1e3 * abs(r.min_clearance - on.min_clearance),
            }
        )
    t, r = best_of(lambda: audit_of(drive, step, 3, **{k: False for k in names}), 1)
    rows.append(
        {
            "shortcut": "all off",
            "time_s": t,
            "ratio": t / t_on,
            "min_clearance_um": 1e3 * r.min_clearance,
            "change_um": 1e3 * abs(r.min_clearance - on.min_clearance),
        }
    )
    return rows


TEMPLATES = sorted((ROOT / "templates").glob("*.toml"))


def bench_chord_tol(quick: bool) -> list[dict]:
    """Chord tolerance: time against error of the refined engine and of the polygon-only engine (issue 8).

    The reference is the polygon engine on 0.01 um outlines (its own error is below 0.02 um);
    D1 involute and cycloidal without coning, one mesh period at 0.25 deg (every tooth angle
    the full revolution meets), where the figures differ between chord tolerances.
    """
    from wgcad.design import with_changes

    rows = []
    tols_um = [10.0, 1.0, 0.3] if quick else [10.0, 3.0, 1.0, 0.3, 0.1, 0.03]
    for name in ("d1_involute", "d1_cycloidal"):
        design = with_changes(
            load_design(ROOT / "templates" / f"{name}.toml"), generator={"cone_length": None, "generator_z": None}
        )
        z_b = design.drive.z_rigid
        n = int(np.ceil(360.0 / z_b / 0.25))
        angles = np.arange(n) * (2 * pi / z_b) / n

        def run(drive, refine):
            return audit(drive, AuditSettings(angles=angles, sections=drive.sections(1), refine=refine))

        ref = run(build_drive(design, tol=1e-5), False)
        for refine in (False, True):
            t_base = None
            for tol_um in tols_um:
                drive = build_drive(design, tol=tol_um * 1e-3)
                t, res = best_of(lambda: run(drive, refine), 1 if refine else 3)
                t_base = t_base or t
                rows.append(
                    {
                        "template": f"{name} ({'refined' if refine else 'polygon'})",
                        "chord_tol_um": tol_um,
                        "vertices_per_tooth": len(drive.flex.period),
                        "time_s": t,
                        "ratio": t / t_base,
                        "min_clearance_um": 1e3 * res.min_clearance,
                        "interference": bool(res.interference),
                        "min_clearance_error_um": 1e3 * abs(res.min_clearance - ref.min_clearance),
                        "entry_gap_error_um": 1e3 * abs(res.entry_gap - ref.entry_gap),
                    }
                )
    return rows


def bench_process(quick: bool) -> dict:
    """Whole-process wall time of ``wgcad audit`` on D1 against the in-process audit time (issue 13)."""
    from wgcad.audit import RunSettings, run_audit

    t_in, _ = best_of(lambda: run_audit(D1, RunSettings()), 1 if quick else 3)
    cmd = [sys.executable, "-m", "wgcad", "audit", str(D1), "--quiet"]
    t_proc, _ = best_of(
        lambda: subprocess.run(cmd, capture_output=True, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}),
        1 if quick else 3,
    )
    t_poly, _ = best_of(lambda: run_audit(D1, RunSettings(refine=False)), 1 if quick else 3)
    return {
        "machine": machine(),
        "in_process_s": t_in,
        "in_process_polygon_only_s": t_poly,
        "whole_process_s": t_proc,
        "import_and_startup_s": t_proc - t_in,
    }


def bench_angle_step(quick: bool) -> list[dict]:
    """Generator-angle step: the sampled minimum against a fine reference (0.02 deg), every template."""
    rows = []
    steps = [5.0, 1.0, 0.5] if quick else [10.0, 5.0, 2.0, 1.0, 0.5, 0.2, 0.1]
    for path in TEMPLATES:
        drive = build_drive(load_design(path))
        ref = audit_of(drive, 0.02, 3)
        t_base = None
        for st in steps:
            t, res = best_of(lambda: audit_of(drive, st, 3), 2)
            t_base = t_base or t
            rows.append(
                {
                    "template": path.stem,
                    "step_deg": st,
                    "time_s": t,
                    "ratio": t / t_base,
                    "min_clearance_error_um": 1e3 * abs(res.min_clearance - ref.min_clearance),
                }
            )
    return rows


def bench_sections(quick: bool) -> list[dict]:
    """Cross-sections over the face width (coned templates): minimum and entry gap against 61 sections."""
    rows = []
    for path in TEMPLATES:
        drive = build_drive(load_design(path))
        if not drive.coned:
            continue
        ref = audit_of(drive, 1.0, 61)
        t_base = None
        for k in [2, 3, 5] if quick else [2, 3, 5, 9, 17]:
            t, res = best_of(lambda: audit_of(drive, 1.0, k), 2)
            t_base = t_base or t
            rows.append(
                {
                    "template": path.stem,
                    "sections": k,
                    "time_s": t,
                    "ratio": t / t_base,
                    "min_clearance_error_um": 1e3 * abs(res.min_clearance - ref.min_clearance),
                    "entry_gap_error_um": 1e3 * abs(res.entry_gap - ref.entry_gap),
                }
            )
    return rows


def bench_engines(quick: bool) -> list[dict]:
    """2D engine against the FCL 3D check on the same pairs: time and difference.

    D4 (no coning: 2D is exact, the 3D solids are prisms) shows the cost of
    not skipping 3D; D1 (coned) the loft's section count against its bound.
    """
    from wgcad.clearance.engine import Scene, tooth_clearance
    from wgcad.clearance.fcl3d import check_tooth

    rows = []
    d4 = build_drive(load_design(ROOT / "templates" / "d4_discrete.toml"))
    sc = Scene(d4)
    phis = np.deg2rad(np.linspace(30.0, 60.0, 7 if quick else 13))
    t2, c2 = best_of(lambda: tooth_clearance(sc, phis, None).min, 5)
    t3, res = best_of(lambda: [check_tooth(sc, float(p)) for p in phis], 1)
    diff = max(abs(1e3 * (r.fcl_distance - c)) for r, c in zip(res, c2))
    rows.append(
        {
            "case": f"D4 prisms, {len(phis)} teeth",
            "engine": "2d",
            "time_s": t2,
            "ratio": 1.0,
            "difference_um": 0.0,
            "bound_um": 0.0,
            "loft_sections": 0,
        }
    )
    rows.append(
        {
            "case": f"D4 prisms, {len(phis)} teeth",
            "engine": "fcl",
            "time_s": t3,
            "ratio": t3 / t2,
            "difference_um": diff,
            "bound_um": 0.0,
            "loft_sections": 0,
        }
    )
    d1 = build_drive(load_design(D1))
    sc1 = Scene(d1)
    phi = np.deg2rad(45.0)
    t2, _ = best_of(lambda: [tooth_clearance(sc1, np.array([phi]), z) for z in d1.sections(3)], 5)
    for n in [5, 9] if quick else [3, 5, 9, 17]:
        t3, r = best_of(lambda: check_tooth(sc1, float(phi), n_sections=n), 1)
        rows.append(
            {
                "case": f"D1 coned, tooth at 45 deg, {n} loft sections",
                "engine": "fcl",
                "time_s": t3,
                "ratio": t3 / t2,
                "difference_um": 1e3 * abs(r.fcl_distance - r.clearance_2d),
                "bound_um": 1e3 * (r.bound or 0.0),
                "loft_sections": n,
            }
        )
    return rows


def bench_templates(quick: bool) -> list[dict]:
    """The audit of every bundled template: full revolution at 0.5 deg, 3 sections, and one mesh period."""
    rows = []
    from wgcad.audit import RunSettings, run_audit

    for path in sorted((ROOT / "templates").glob("*.toml")):
        design = load_design(path)
        drive = build_drive(design)
        if design.imperfections.any and design.drive.fixed == "rigid":
            # an imperfect drive is audited with its errors (the engine alone would audit its perfect twin); its
            # errors break the mesh period, so there is no one-period figure
            t_full, (_, r) = best_of(lambda: run_audit(path, RunSettings(step_deg=0.5, sections=3)), 1 if quick else 3)
            t_1p = float("nan")
        else:
            t_full, r = best_of(lambda: audit_of(drive, 0.5, 3), 1 if quick else 3)
            mesh = 360.0 / drive.design.drive.z_rigid
            ang = np.deg2rad(np.arange(0.0, mesh, 0.5))
            t_1p, _ = best_of(lambda: audit(drive, AuditSettings(angles=ang, sections=drive.sections(3))), 15)
        rows.append(
            {
                "template": path.stem,
                "full_revolution_s": t_full,
                "one_period_s": t_1p,
                "samples": r.counts["samples"],
                "evaluated": r.counts["evaluated"],
                "min_clearance_um": 1e3 * r.min_clearance,
            }
        )
    return rows


def table_md(rows: list[dict]) -> str:
    keys = list(rows[0])
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(f"{r[k]:.4g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    return "\n".join(lines)


def plot(rows, x, title, path, y="min_clearance_error_um"):
    """Time against error, one line per template (labels: the knob's value)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5), dpi=90)
    groups = {}
    for r in rows:
        groups.setdefault(r.get("template", ""), []).append(r)
    floor = 1e-7  # errors of exactly 0 drawn at the floor of the log axis
    for name, rs in groups.items():
        ts = [r["time_s"] for r in rs]
        es = [max(r[y], floor) for r in rs]
        ax.loglog(ts, es, "o-", label=name or None)
        for r, t, e in zip(rs, ts, es):
            ax.annotate(f"{r[x]:g}", (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("run time, s")
    ax.set_ylabel(y.replace("_", " ") + f" (0 drawn at {floor:g})")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, which="both")
    if any(groups):
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument(
        "--only", choices=["audit", "process", "templates", "shortcuts", "chord", "step", "sections", "engines"]
    )
    args = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    report = {"machine": machine()}
    md = [
        f"# wgcad benchmarks\n\nMachine: {machine()}. Designs: the bundled templates (D1 involute where one is named).\n"
    ]
    jobs = [
        ("audit", bench_audit, None),
        ("process", bench_process, None),
        ("templates", bench_templates, None),
        ("shortcuts", bench_shortcuts, None),
        ("engines", bench_engines, None),
        ("chord", bench_chord_tol, ("chord_tol_um", "Chord tolerance (label: um)")),
        ("step", bench_angle_step, ("step_deg", "Generator-angle step (label: deg)")),
        ("sections", bench_sections, ("sections", "Cross-sections (label: count)")),
    ]
    for name, fn, plot_spec in jobs:
        if args.only and args.only != name:
            continue
        t = time.perf_counter()
        res = fn(args.quick)
        print(f"{name}: {time.perf_counter() - t:.1f} s", file=sys.stderr)
        report[name] = res
        if isinstance(res, list):
            md.append(f"## {name}\n\n{table_md(res)}\n")
            if plot_spec:
                plot(res, plot_spec[0], plot_spec[1], OUT / f"{name}.png")
            if name == "engines":
                lofts = [r for r in res if r["loft_sections"]]
                plot(
                    lofts,
                    "loft_sections",
                    "FCL check of a coned D1 tooth: loft sections (label)",
                    OUT / "engines.png",
                    y="bound_um",
                )
            keys = list(res[0])
            (OUT / f"{name}.csv").write_text(
                ",".join(keys) + "\n" + "\n".join(",".join(str(r[k]) for k in keys) for r in res) + "\n"
            )
        else:
            md.append(
                f"## {name}\n\n"
                + "\n".join(f"- {k}: {v:.6g}" if isinstance(v, float) else f"- {k}: {v}" for k, v in res.items())
                + "\n"
            )
    (OUT / "report.json").write_text(json.dumps(report, indent=2) + "\n")
    (OUT / "README.md").write_text("\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
