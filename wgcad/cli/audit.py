"""``wgcad audit``: clearance and interference over the generator cycle, baselines, pictures."""

from __future__ import annotations

import argparse
import os
import sys
import textwrap

from ..errors import DesignError, OutputError
from ..export.files.audit import plot_paths, write_audit_files
from ..export.formats.json_text import json_text
from ..regression import format_drifts, load_baseline
from ..report.audit import audit_summary
from ..report.sections import section_lines
from ..services.audit import FLAGS, RunSettings
from ..services.audit_report import audit_document, baseline_document
from .bounds import bounded
from .common import (
    COMMAND_HELP,
    EXIT_INTERFERENCE,
    EXIT_OK,
    Progress,
    add_memory_flag,
    angle_count,
    epilog,
    require_picture_extras,
    want_progress,
    whole_number,
)
from .load import register_args, run_load
from .outputs import STDOUT, check_output_file, write_stdout

__all__ = ["register", "cmd_audit"]


def _audit_summary(name: str, res: dict) -> str:
    return audit_summary(name, res)


def _check_outputs(args) -> None:
    """Every output path is judged before the design is read: a refused run computes and writes nothing."""
    require_picture_extras(args)
    inputs = [args.design, args.baseline]
    if args.json == STDOUT and args.write_baseline == STDOUT:
        raise OutputError("--json - and --write-baseline -: only one of them can go to standard output")
    seen = {}
    targets = [("--json", args.json), ("--write-baseline", args.write_baseline)]
    if args.plot:
        if args.plot == STDOUT:
            raise OutputError("--plot: writes three PNG files, so it needs a path, not - (standard output)")

        targets += [("--plot", p) for _, p in plot_paths(args.plot)]
    if args.html:
        if args.html == STDOUT:
            raise OutputError("--html: writes a page, so it needs a path, not - (standard output)")
        targets.append(("--html", args.html))
    for flag, path in targets:
        if not path or path == STDOUT:
            continue
        key = os.path.abspath(path)
        if key in seen:
            raise OutputError(f"{flag}: {path} is also the file of {seen[key]}")
        seen[key] = flag
        check_output_file(path, flag=flag, inputs=inputs, stdout_ok=flag not in ("--plot", "--html"))


def _run_settings(args, base: dict | None):
    """The run's settings: a baseline's (its figures are only comparable at its own), else the flags'."""
    if base is not None:
        st = base["settings"]
        return RunSettings(
            step_deg=float(st["step_deg"]),
            sections=int(st["sections"]),
            chord_tol_um=float(st["chord_tol_um"]),
            interference_tol_um=float(st["interference_tol_um"]),
            max_memory_mb=args.max_memory_mb,
        )
    step = 360.0 / args.angles if args.angles else args.step_deg
    off = args.no_shortcuts
    return RunSettings(
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


def cmd_audit(args) -> int:
    if args.torque_nm is not None:  # under load: cli/load.py
        if args.by_section:
            raise DesignError("--by-section", "audits the unloaded drive; the load audit reports every section already")

        _check_outputs(args)
        return run_load(args)

    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("loading modules")
    _check_outputs(args)

    bar.set(0.0, "reading the design")

    base = None
    if args.baseline:
        base = load_baseline(args.baseline)
    rs = _run_settings(args, base)
    rs.check(FLAGS)
    # the engine reports (done, total, stage); it fills the bar up to 90 % (95 % without pictures)
    work_end = 0.6 if args.plot else (0.9 if args.engine == "2d" else 0.8)

    try:
        run = audit_document(
            args.design,
            rs,
            engine=args.engine,
            baseline=base,
            baseline_path=args.baseline,
            plot=bool(args.plot),
            progress=bar.span(0.02, work_end, "clearance"),
            on_stage=lambda name: bar.set(work_end, name),
            by_section=args.by_section,
        )
    except DesignError as exc:  # a run setting the design cannot take: named by the flag the user typed
        if exc.field in FLAGS:
            raise DesignError(FLAGS[exc.field], exc.rule) from None
        raise
    res, drifts = run.doc, run.drifts
    base_doc = baseline_document(run, rs, args.design) if args.write_baseline else None
    write_audit_files(
        run,
        json_path=args.json if args.json != STDOUT else None,
        baseline=base_doc,
        baseline_path=args.write_baseline if args.write_baseline != STDOUT else None,
        plot=args.plot,
        html=args.html,
        on_pictures=lambda: bar.set(0.9 if args.engine == "2d" else 0.95, "pictures"),
    )
    bar.set(1.0, "done")
    bar.close()
    if args.json == STDOUT:
        write_stdout(json_text(res) + "\n")
    if args.write_baseline == STDOUT:
        write_stdout(json_text(base_doc) + "\n")
    if not args.quiet:
        # with a JSON document on stdout, the summary for people goes to stderr
        stream = sys.stderr if STDOUT in (args.json, args.write_baseline) else sys.stdout
        lines = [_audit_summary(res["design"], res)]
        if "by_section" in res:
            lines += section_lines(res["by_section"], res.get("balanced_taper"))
        lines += [f"  NOT CHECKED: {n}" for n in res["not_checked"]]
        if "fcl" in res:
            lines.append(f"  FCL 3D check of the pairs the 2D engine singled out: {res['fcl']['summary']}")
        if drifts is not None:
            lines.append(f"  baseline {args.baseline}: {format_drifts(drifts)}")
        if stream is sys.stdout:
            write_stdout("\n".join(lines) + "\n")
        else:
            print("\n".join(lines), file=sys.stderr)
    return EXIT_INTERFERENCE if run.failed else EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    a = sub.add_parser(
        "audit",
        help=COMMAND_HELP["audit"],
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
        epilog=epilog(
            one="interference found, or drift from --baseline; with --torque-nm: the entry gap closes under the load",
            model="only with --torque-nm: the elastic model",
            five="--plot needs wgcad[plots], --html wgcad[html]",
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    a.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    grp = a.add_mutually_exclusive_group()
    grp.add_argument("--angles", type=angle_count, metavar="N", help="N generator angles over a full revolution")
    grp.add_argument(
        "--step-deg", type=bounded("audit", "--step-deg"), default=0.5, help="generator-angle step, deg (default 0.5)"
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
        type=bounded("audit", "--sections"),
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
        type=bounded("audit", "--chord-tol-um"),
        default=1.0,
        help="largest distance between outline and exact curve, um (default 1)",
    )
    a.add_argument(
        "--interference-tol-um",
        type=bounded("audit", "--interference-tol-um"),
        default=1.0,
        metavar="UM",
        help="penetration still reported as contact, not interference, um, 0..1000 (default 1)",
    )
    _output_flags(a)
    _shortcut_flags(a)
    a.add_argument(
        "--progress",
        action="store_true",
        help="progress bar (fraction, ETA) on stderr even when it is not a terminal or with --quiet; "
        "by default it is drawn only on a terminal",
    )
    a.add_argument(
        "--by-section",
        action="store_true",
        help="also audit every section of a coned cup on its own: its tooth offset (face modification), depth of "
        "engagement and smallest clearance side by side (one more exact audit per section; JSON by_section)",
    )
    a.add_argument("--quiet", action="store_true", help="print no summary")
    add_memory_flag(a)

    register_args(a)
    a.set_defaults(func=cmd_audit)


def _output_flags(a) -> None:
    """The audit's files: JSON, plots, page, baselines."""
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
        "--html",
        metavar="PATH",
        help="write one self-contained interactive page (zoomable figures, the tables; nothing fetched when viewed)",
    )
    a.add_argument(
        "--write-baseline",
        metavar="BASE.json",
        help="record the key figures with their tolerances (- for standard output)",
    )
    a.add_argument("--baseline", metavar="BASE.json", help="recompute with the baseline's settings; exit 1 on drift")


def _shortcut_flags(a) -> None:
    """The switches that turn the audit's shortcuts and its refinement off."""
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
