"""``wgcad audit``: clearance and interference over the generator cycle, baselines, pictures."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from .common import EPILOG, EXIT_INTERFERENCE, EXIT_OK, add_memory_flag, angle_count, positive_float, whole_number

__all__ = ["register", "cmd_audit"]


def _audit_summary(name: str, res: dict) -> str:
    from ..report.audit import audit_summary  # shaped in the report layer (issue 8)

    return audit_summary(name, res)


def _plot_paths(plot) -> list[tuple[str, Path]]:
    p = Path(plot)
    return [(suffix, p.with_name(f"{p.stem}_{suffix}.png")) for suffix in ("profile", "vs_angle", "tightest")]


def _check_outputs(args) -> None:
    """Every output path is judged before the design is read: a refused run computes and writes nothing."""
    from ..errors import OutputError
    from .outputs import STDOUT, check_output_file

    inputs = [args.design, args.baseline]
    if args.json == STDOUT and args.write_baseline == STDOUT:
        raise OutputError("--json - and --write-baseline -: only one of them can go to standard output")
    seen = {}
    targets = [("--json", args.json), ("--write-baseline", args.write_baseline)]
    if args.plot:
        if args.plot == STDOUT:
            raise OutputError("--plot: writes three PNG files, so it needs a path, not - (standard output)")
        targets += [("--plot", p) for _, p in _plot_paths(args.plot)]
    for flag, path in targets:
        if not path or path == STDOUT:
            continue
        key = os.path.abspath(path)
        if key in seen:
            raise OutputError(f"{flag}: {path} is also the file of {seen[key]}")
        seen[key] = flag
        check_output_file(path, flag=flag, inputs=inputs, stdout_ok=flag != "--plot")


def cmd_audit(args) -> int:
    if args.torque_nm is not None:  # under load: cli/load.py
        from .load import run_load

        return run_load(args)
    from .common import Progress, want_progress
    from .outputs import STDOUT, write_stdout

    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("loading modules")
    _check_outputs(args)
    from ..audit import RunSettings, run_audit

    bar.set(0.0, "reading the design")

    base = None
    if args.baseline:
        from ..regression import load_baseline

        base = load_baseline(args.baseline)
    if base is not None:
        st = base["settings"]
        rs = RunSettings(
            step_deg=float(st["step_deg"]),
            sections=int(st["sections"]),
            chord_tol_um=float(st["chord_tol_um"]),
            interference_tol_um=float(st["interference_tol_um"]),
            max_memory_mb=args.max_memory_mb,
        )
    else:
        step = 360.0 / args.angles if args.angles else args.step_deg
        off = args.no_shortcuts
        rs = RunSettings(
            step_deg=step,
            sections=args.sections,
            chord_tol_um=args.chord_tol_um,
            interference_tol_um=args.interference_tol_um,
            use_period=not (off or args.no_mesh_period),
            use_waves=not (off or args.no_wave_symmetry),
            use_mirror=not (off or args.no_mirror),
            cull=not (off or args.no_culling),
            bound=not (off or args.no_bound),
            max_memory_mb=args.max_memory_mb,
            refine=not args.no_refine,
            turns=args.turns,
        )
    rs.check()
    # the engine reports (done, total, stage); it fills the bar up to 90 % (95 % without pictures)
    work_end = 0.6 if args.plot else (0.9 if args.engine == "2d" else 0.8)
    drive, result = run_audit(args.design, rs, progress=bar.span(0.02, work_end, "clearance"))
    from ..report.audit import audit_json

    res = audit_json(result)
    res["design"] = drive.design.drive.name
    res["source"] = drive.design.source
    from .common import not_modelled

    imperfect = bool(res["settings"].get("imperfections"))
    res["not_checked"] = not_modelled(drive.design, "this audit", imperfections=imperfect)
    if imperfect:
        res["not_checked"] += _imperfect_not_checked(args, res["settings"])
    if args.engine in ("fcl", "both"):
        bar.set(work_end, "3D check (fcl)")
        from ..clearance.fcl3d import verify_worst

        imp = None
        if imperfect:
            from ..placement.imperfect import Imperfections

            imp = Imperfections.from_spec(drive.design.imperfections)
        res["fcl"] = verify_worst(drive, result, imp=imp)
        if args.engine == "fcl":
            res["settings"]["engine"] = "fcl (3D check of the pairs the 2D engine singles out)"
        else:
            res["settings"]["engine"] = "2d + fcl"
    drifts = None
    if base is not None:
        from ..regression import baseline_figures, compare

        drifts = compare(base, baseline_figures(drive, res))
        res["baseline"] = {"path": str(args.baseline), "drifts": [d.__dict__ for d in drifts]}
    res_text = json.dumps(res, allow_nan=False, indent=2) + "\n"
    base_text = None
    if args.write_baseline:
        from ..regression import make_baseline

        doc = make_baseline(
            str(args.design),
            {
                k: v
                for k, v in rs.as_dict().items()
                if k in ("step_deg", "sections", "chord_tol_um", "interference_tol_um")
            },
            drive,
            res,
        )
        base_text = json.dumps(doc, allow_nan=False, indent=2) + "\n"
    files = [(args.json, res_text), (args.write_baseline, base_text)]
    if any(p and p != STDOUT for p, _ in files) or args.plot:
        from ..atomic import atomic_batch

        with atomic_batch() as batch:
            for path, text in files:
                if path and path != STDOUT:
                    Path(batch.temp_path(path)).write_text(text)
            if args.plot:
                bar.set(0.9 if args.engine == "2d" else 0.95, "pictures")
                pngs = dict(_audit_pngs(drive, result))
                for suffix, path in _plot_paths(args.plot):
                    Path(batch.temp_path(path)).write_bytes(pngs[suffix])
    bar.set(1.0, "done")
    bar.close()
    for path, text in files:
        if path == STDOUT:
            write_stdout(text)
    if not args.quiet:
        # with a JSON document on stdout, the summary for people goes to stderr
        stream = sys.stderr if STDOUT in (args.json, args.write_baseline) else sys.stdout
        lines = [_audit_summary(res["design"], res)]
        lines += [f"  NOT CHECKED: {n}" for n in res["not_checked"]]
        if "fcl" in res:
            lines.append(f"  FCL 3D check of the pairs the 2D engine singled out: {res['fcl']['summary']}")
        if drifts is not None:
            from ..regression import format_drifts

            lines.append(f"  baseline {args.baseline}: {format_drifts(drifts)}")
        if stream is sys.stdout:
            write_stdout("\n".join(lines) + "\n")
        else:
            print("\n".join(lines), file=sys.stderr)
    if drifts:
        return EXIT_INTERFERENCE
    return EXIT_INTERFERENCE if res["interference"] else EXIT_OK


def _imperfect_not_checked(args, settings: dict) -> list[str]:
    """What the audit of an imperfect drive (wgcad.clearance.imperfect) leaves to the perfect drive, said in the summary."""
    notes = []
    full = settings.get("full_cycle_turns")
    done = settings.get("generator_turns", 1.0)
    if not settings.get("shortcuts_that_hold", {}).get("one_generator_turn", True) and full and done < full - 1e-9:
        notes.append(
            f"generator turns beyond the first {done:g} of the {full}-turn cycle: the flexspline-borne errors "
            f"(run-out, eccentricity, e_h^g) meet the housing's and the cam's in other phases there "
            f"(--turns full sweeps all {full}, {full / max(done, 1e-9):g}x the samples)"
        )
    if args.plot:
        notes.append(
            "--plot with [imperfections]: the profile picture shows the perfect drive's passage (the vs_angle picture "
            "shows every imperfect passage's entry gap, the tightest-spot picture the imperfect parts)"
        )
    return notes


def _audit_pngs(drive, result):
    import numpy as np
    import shapely

    from ..clearance.engine import Scene, clearance_profile, clearance_vs_angle
    from ..export.figures import clearance_profile_png, clearance_vs_angle_png, tightest_spot_png
    from ..placement import tooth_pose, transform

    scene = Scene(drive)
    imperfect = bool(result.settings.get("imperfections"))
    perfect_note = " (perfect drive)" if imperfect else ""
    secs = [None] if not drive.coned else [s for s in result.settings["sections_z_mm"]]
    prof = clearance_profile(scene, secs)
    from ..report.audit import audit_json

    doc = audit_json(result)
    w, e = doc["worst"], doc["entry"]
    name = drive.design.drive.name
    ent = result.findings["entry_crossing"].details
    extra = {}
    if imperfect and "perfect_gaps" in ent:
        # the perfect drive's curve with its own entry crossing (on the exact curves) marked, and the imperfect
        # parts' entry gap beside it (every passage has its own picture)
        from ..clearance.entry import entry_crossings

        gaps = entry_crossings(scene, secs, exact=True)
        i = int(np.nanargmin([g for g, _ in gaps]))
        entry_deg, entry_um = float(np.rad2deg(gaps[i][1])), 1e3 * gaps[i][0]
        entry_label = "perfect drive's entry gap"
        if np.isfinite(result.entry_gap):
            extra = {
                "entry2_deg": e["tooth_angle_deg"],
                "entry2_um": 1e3 * result.entry_gap,
                "entry2_label": f"imperfect parts' entry gap Delta (tooth {e.get('pinch_tooth' if e.get('kind') == 'pinch' else 'tooth')}, the smallest of "
                f"{ent.get('passages', 0)} passages)",
            }
    else:
        entry_deg, entry_um, entry_label = e["tooth_angle_deg"], 1e3 * result.entry_gap, "entry gap Delta"
    data = {
        "phi_deg": np.rad2deg(prof["phi"]),
        "sections": [
            {"z": s["z"], "working_um": 1e3 * s["working"], "nonworking_um": 1e3 * s["nonworking"]}
            for s in prof["sections"]
        ],
        "entry_deg": entry_deg,
        "entry_um": entry_um,
        "entry_label": entry_label,
        **extra,
        "worst_label": "imperfect parts' minimum" if imperfect else "minimum",
        "worst_deg": w["tooth_angle_deg"],
        "worst_um": w["clearance_um"],
        "tol_um": 1e3 * result.interference_tol,
    }
    yield (
        "profile",
        clearance_profile_png(
            data, f"{name}: clearance of a flexspline tooth along its passage (every tooth follows it){perfect_note}"
        ),
    )
    mesh = 360.0 / drive.design.drive.z_rigid
    if imperfect and "all_passages" in ent:
        # the errors break the mesh period: every passage of a tooth through the entry has its own gap
        from ..export.imperfect_figures import entry_passages_png

        a = ent["all_passages"]
        yield (
            "vs_angle",
            entry_passages_png(
                np.rad2deg(a["phi_h"]),
                1e3 * a["gap"],
                a["section"],
                secs,
                [1e3 * g for g in ent["perfect_gaps"]],
                1e3 * result.interference_tol,
                f"{name}: entry gap of every passage of a tooth through the entry, imperfect parts "
                f"({result.settings.get('generator_turns', 1):g} generator turn(s); the audit's smallest is refined on the exact curves)",
            ),
        )
    else:
        ang = np.deg2rad(np.linspace(0.0, 3 * mesh, 601))
        wv, nv = clearance_vs_angle(scene, prof, ang)
        yield (
            "vs_angle",
            clearance_vs_angle_png(
                np.rad2deg(ang),
                1e3 * wv,
                1e3 * nv,
                1e3 * result.interference_tol,
                f"{name}: smallest clearance over all teeth; periodic with the mesh period {mesh:.4f} deg (3 shown){perfect_note}",
            ),
        )
    # the teeth around the tightest spot, at the worst sample's generator angle and section
    phi_h = np.deg2rad(w["generator_angle_deg"])
    z = w["section_z_mm"]
    d = drive.design.drive
    k = (w["tooth"] + np.arange(-3, 4)) % d.z_flex
    mat = 2 * np.pi * k / d.z_flex + phi_h / scene.ratios["u_hg"]
    rot, shift = tooth_pose(scene.law(z), mat - phi_h, drive.r_m, frame_angle=phi_h)
    if imperfect:
        # the imperfect drive's own teeth, where the audit found its tightest spot
        from ..clearance.imperfect import ImperfectScene, flex_poses_batch
        from ..placement.imperfect import Imperfections

        imp = Imperfections.from_spec(drive.design.imperfections)
        scene = ImperfectScene.from_scene(scene, imp)
        rot, shift = flex_poses_batch(drive, imp, np.full(len(k), phi_h), k, [z])[0]
        shift = scene.relative(shift)  # drawn in the frame of the rigid gear's own centre
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
    yield (
        "tightest",
        tightest_spot_png(
            teeth,
            labels,
            rig,
            overlaps,
            f"{name}{' (imperfect parts)' if imperfect else ''}: tightest spot, tooth {w['tooth']} at generator angle {w['generator_angle_deg']:g} deg{sec}: "
            f"{w['clearance_um']:.2f} um ({w['location']})",
        ),
    )


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse
    import textwrap

    a = sub.add_parser(
        "audit",
        help="clearance and interference over the generator cycle; exit 1 on interference or baseline drift",
        description=textwrap.fill(
            "Signed clearance of every flexspline tooth against its rigid neighbours over a full generator "
            "revolution (and several sections when coned): the worst spot, entry gap and pinch, backlash. "
            "Prints a summary; --json - puts the JSON on standard output and the summary on standard error "
            "(--quiet drops it), so the audit can be piped. A design's [imperfections] are honoured: every tooth is "
            "posed with its run-out, eccentricity and cam offset (the mesh-period, wave and mirror shortcuts do not "
            "hold then; the entry gap and pinch are those of every passage of a tooth through the entry; --turns "
            "sweeps more of the error cycle).",
            width=79,
        ),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    a.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    grp = a.add_mutually_exclusive_group()
    grp.add_argument("--angles", type=angle_count, metavar="N", help="N generator angles over a full revolution")
    grp.add_argument(
        "--step-deg", type=positive_float(0.0, 90.0, "deg"), default=0.5, help="generator-angle step, deg (default 0.5)"
    )
    a.add_argument(
        "--turns",
        type=whole_number(1, 10_000, "generator turns", {"full": None}),
        default=1,
        metavar="N|full",
        help="generator turns swept for an imperfect drive ([imperfections]), or 'full' for the whole cycle "
        "(the numerator of |u_hg|: 100 for 200/202 teeth; default 1)",
    )
    a.add_argument(
        "--sections",
        type=int,
        default=3,
        metavar="N",
        help="cross-sections over the face width when the flexspline is coned, 1..200 (default 3)",
    )
    a.add_argument(
        "--engine",
        choices=("2d", "fcl", "both"),
        default="2d",
        help="2d (default); fcl/both: also check the tightest pairs with 3D solids in python-fcl",
    )
    a.add_argument(
        "--chord-tol-um",
        type=positive_float(0.0, 100.0, "um"),
        default=1.0,
        help="largest distance between outline and exact curve, um (default 1)",
    )
    a.add_argument(
        "--interference-tol-um",
        type=float,
        default=1.0,
        metavar="UM",
        help="penetration still reported as contact, not interference, um, 0..1000 (default 1)",
    )
    a.add_argument(
        "--json",
        metavar="PATH",
        help="write the results as JSON to PATH (a new or regular file), or to standard output with -",
    )
    a.add_argument(
        "--plot",
        metavar="PATH",
        help="write PNGs PATH_profile.png, PATH_vs_angle.png, PATH_tightest.png (PATH without .png)",
    )
    a.add_argument(
        "--write-baseline",
        metavar="BASE.json",
        help="record the key figures with their tolerances (- for standard output)",
    )
    a.add_argument("--baseline", metavar="BASE.json", help="recompute with the baseline's settings; exit 1 on drift")
    a.add_argument(
        "--no-shortcuts",
        action="store_true",
        help="compute everything (no mesh period, symmetries, culling or bounding)",
    )
    a.add_argument(
        "--no-mesh-period",
        action="store_true",
        help="evaluate every (generator angle, tooth) sample, not one per tooth angle from the major axis",
    )
    a.add_argument(
        "--no-wave-symmetry", action="store_true", help="do not fold tooth angles into one wave of the generator"
    )
    a.add_argument(
        "--no-mirror",
        action="store_true",
        help="do not use the mirror symmetry c(-phi) = c(phi) with the flanks swapped",
    )
    a.add_argument(
        "--no-culling",
        action="store_true",
        help="also evaluate teeth radially clear of all rigid material, and the third-nearest rigid tooth everywhere",
    )
    a.add_argument(
        "--no-refine",
        action="store_true",
        help="report the figures of the sampled outlines (within 2 chord tolerances of the true curves) instead of "
        "refining them on the exact tooth curves: about 5x faster, not exact",
    )
    a.add_argument(
        "--no-bound",
        action="store_true",
        help="evaluate every sample (no branch and bound on the Lipschitz lower bound)",
    )
    a.add_argument(
        "--progress",
        action="store_true",
        help="progress bar (fraction, ETA) on stderr even when it is not a terminal or with --quiet; "
        "by default it is drawn only on a terminal",
    )
    a.add_argument("--quiet", action="store_true", help="print no summary")
    add_memory_flag(a)
    from .load import register_args

    register_args(a)
    a.set_defaults(func=cmd_audit)
