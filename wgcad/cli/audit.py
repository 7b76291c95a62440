"""``wgcad audit``: clearance and interference over the generator cycle, baselines, pictures."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from .common import EPILOG, EXIT_INTERFERENCE, EXIT_OK, Progress, add_memory_flag, angle_count, positive_float

__all__ = ["register", "cmd_audit"]


def _audit_summary(name: str, res: dict) -> str:
    from ..report.audit import audit_summary  # shaped in the report layer (issue 8)

    return audit_summary(name, res)


def cmd_audit(args) -> int:
    if args.torque_nm is not None:  # under load: cli/load.py
        from .load import run_load

        return run_load(args)
    from ..audit import RunSettings, run_audit
    from ..export.atomic import atomic_batch, ensure_writable_dir
    from ..regression import baseline_figures, compare, format_drifts, load_baseline, make_baseline

    base = load_baseline(args.baseline) if args.baseline else None
    if base is not None:
        st = base["settings"]
        rs = RunSettings(step_deg=float(st["step_deg"]), sections=int(st["sections"]),
                         chord_tol_um=float(st["chord_tol_um"]), interference_tol_um=float(st["interference_tol_um"]),
                         max_memory_mb=args.max_memory_mb)
    else:
        step = 360.0 / args.angles if args.angles else args.step_deg
        off = args.no_shortcuts
        rs = RunSettings(step_deg=step, sections=args.sections, chord_tol_um=args.chord_tol_um,
                         interference_tol_um=args.interference_tol_um,
                         use_period=not (off or args.no_mesh_period), use_waves=not (off or args.no_wave_symmetry),
                         use_mirror=not (off or args.no_mirror), cull=not (off or args.no_culling),
                         bound=not (off or args.no_bound), max_memory_mb=args.max_memory_mb)
    rs.check()
    for path in (args.json, args.plot, args.write_baseline):
        if path:
            ensure_writable_dir(Path(path).parent if str(Path(path).parent) else Path("."))
    drive, result = run_audit(args.design, rs, progress=Progress(args.progress or sys.stderr.isatty()))
    res = result.to_json()
    res["design"] = drive.design.drive.name
    res["source"] = drive.design.source
    if args.engine in ("fcl", "both"):
        from ..clearance.fcl3d import verify_worst

        res["fcl"] = verify_worst(drive, result)
        if args.engine == "fcl":
            res["settings"]["engine"] = "fcl (3D check of the pairs the 2D engine singles out)"
        else:
            res["settings"]["engine"] = "2d + fcl"
    drifts = None
    if base is not None:
        drifts = compare(base, baseline_figures(drive, res))
        res["baseline"] = {"path": str(args.baseline), "drifts": [d.__dict__ for d in drifts]}
    with atomic_batch() as batch:
        if args.json:
            Path(batch.temp_path(args.json)).write_text(json.dumps(res, indent=2) + "\n")
        if args.write_baseline:
            doc = make_baseline(str(args.design), {k: v for k, v in rs.as_dict().items()
                                                    if k in ("step_deg", "sections", "chord_tol_um", "interference_tol_um")},
                                drive, res)
            Path(batch.temp_path(args.write_baseline)).write_text(json.dumps(doc, indent=2) + "\n")
        if args.plot:
            for suffix, png in _audit_pngs(drive, result):
                p = Path(args.plot)
                Path(batch.temp_path(p.with_name(f"{p.stem}_{suffix}.png"))).write_bytes(png)
    if not args.quiet:
        print(_audit_summary(res["design"], res))
        if "fcl" in res:
            f = res["fcl"]
            print(f"  FCL 3D check of the pairs the 2D engine singled out: {f['summary']}")
        if drifts is not None:
            print(f"  baseline {args.baseline}: {format_drifts(drifts)}")
    if drifts:
        return EXIT_INTERFERENCE
    return EXIT_INTERFERENCE if res["interference"] else EXIT_OK


def _audit_pngs(drive, result):
    import numpy as np
    import shapely

    from ..clearance.engine import Scene, clearance_profile, clearance_vs_angle
    from ..export.figures import clearance_profile_png, clearance_vs_angle_png, tightest_spot_png
    from ..placement import tooth_pose, transform

    scene = Scene(drive)
    secs = [None] if not drive.coned else [s for s in result.settings["sections_z_mm"]]
    prof = clearance_profile(scene, secs)
    w = result.worst
    e = result.entry
    name = drive.design.drive.name
    data = {
        "phi_deg": np.rad2deg(prof["phi"]),
        "sections": [{"z": s["z"], "working_um": 1e3 * s["working"], "nonworking_um": 1e3 * s["nonworking"]} for s in prof["sections"]],
        "entry_deg": e["tooth_angle_deg"],
        "entry_um": 1e3 * result.entry_gap,
        "worst_deg": w["tooth_angle_deg"],
        "worst_um": w["clearance_um"],
        "tol_um": 1e3 * result.interference_tol,
    }
    yield "profile", clearance_profile_png(data, f"{name}: clearance of a flexspline tooth along its passage (every tooth follows it)")
    mesh = 360.0 / drive.design.drive.z_rigid
    ang = np.deg2rad(np.linspace(0.0, 3 * mesh, 601))
    wv, nv = clearance_vs_angle(scene, prof, ang)
    yield "vs_angle", clearance_vs_angle_png(np.rad2deg(ang), 1e3 * wv, 1e3 * nv, 1e3 * result.interference_tol,
                                             f"{name}: smallest clearance over all teeth; periodic with the mesh period {mesh:.4f} deg (3 shown)")
    # the teeth around the tightest spot, at the worst sample's generator angle and section
    phi_h = np.deg2rad(w["generator_angle_deg"])
    z = w["section_z_mm"]
    d = drive.design.drive
    k = (w["tooth"] + np.arange(-3, 4)) % d.z_flex
    mat = 2 * np.pi * k / d.z_flex + phi_h / scene.ratios["u_hg"]
    rot, shift = tooth_pose(scene.law(z), mat - phi_h, drive.r_m, frame_angle=phi_h)
    teeth = transform(scene.flex_local, rot, shift)
    lo, up, _ = scene.neighbours(shift, rot)
    rig_idx = np.unique(np.concatenate([lo, up]))
    rig = scene.rigid_pts[rig_idx]
    overlaps = []
    for t in teeth[3:4]:  # the worst tooth
        a = shapely.Polygon(t)
        for j in rig_idx:
            inter = a.intersection(scene.rigid_geoms[j])
            for g in getattr(inter, "geoms", [inter]):
                if g.geom_type == "Polygon" and not g.is_empty:
                    overlaps.append(np.asarray(g.exterior.coords))
    labels = [f"{np.rad2deg(((p + np.pi) % (2 * np.pi)) - np.pi):.1f} deg" for p in (mat - phi_h)]
    sec = "" if z is None else f", section z = {z:g} mm"
    yield "tightest", tightest_spot_png(teeth, labels, rig, overlaps,
                                        f"{name}: tightest spot, tooth {w['tooth']} at generator angle {w['generator_angle_deg']:g} deg{sec}: "
                                        f"{w['clearance_um']:.2f} um ({w['location']})")



def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    a = sub.add_parser("audit", help="clearance and interference over the generator cycle; exit 1 on interference or baseline drift",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("design")
    grp = a.add_mutually_exclusive_group()
    grp.add_argument("--angles", type=angle_count, metavar="N", help="N generator angles over a full revolution")
    grp.add_argument("--step-deg", type=positive_float(0.0, 90.0, "deg"), default=0.5, help="generator-angle step, deg (default 0.5)")
    a.add_argument("--sections", type=int, default=3, help="cross-sections over the face width when the flexspline is coned (default 3)")
    a.add_argument("--engine", choices=("2d", "fcl", "both"), default="2d",
                   help="2d (default); fcl/both: also check the tightest pairs with 3D solids in python-fcl")
    a.add_argument("--chord-tol-um", type=positive_float(0.0, 100.0, "um"), default=1.0,
                   help="largest distance between outline and exact curve, um (default 1)")
    a.add_argument("--interference-tol-um", type=float, default=1.0, help="penetration reported as contact, um (default 1)")
    a.add_argument("--json", metavar="PATH", help="write the results as JSON")
    a.add_argument("--plot", metavar="PATH", help="write PNGs PATH_profile.png, PATH_vs_angle.png, PATH_tightest.png (PATH without .png)")
    a.add_argument("--write-baseline", metavar="BASE.json", help="record the key figures with their tolerances")
    a.add_argument("--baseline", metavar="BASE.json", help="recompute with the baseline's settings; exit 1 on drift")
    a.add_argument("--no-shortcuts", action="store_true", help="compute everything (no mesh period, symmetries, culling or bounding)")
    a.add_argument("--no-mesh-period", action="store_true")
    a.add_argument("--no-wave-symmetry", action="store_true")
    a.add_argument("--no-mirror", action="store_true")
    a.add_argument("--no-culling", action="store_true")
    a.add_argument("--no-bound", action="store_true")
    a.add_argument("--progress", action="store_true", help="progress bar on stderr even when it is not a terminal")
    a.add_argument("--quiet", action="store_true")
    add_memory_flag(a)
    from .load import register_args

    register_args(a)
    a.set_defaults(func=cmd_audit)
