"""``wgcad sector``: the sectored rigid gear of a discrete-motion drive: heights both ways, motion law, audit, DXF/STL."""

from __future__ import annotations

from ..export.json_text import json_text
from .common import EXIT_INTERFERENCE, EXIT_OK, add_memory_flag, epilog, out_dir, positive_float

__all__ = ["register", "cmd_sector"]


def cmd_sector(args) -> int:
    from ..atomic import check_writable_dir
    from ..design import load_design
    from ..design.budget import check_sector_budget
    from ..sector.scene import DEFAULT_STEP_DEG

    design = load_design(args.design)
    check_sector_budget(
        design.drive.z_flex, DEFAULT_STEP_DEG if args.step_deg is None else args.step_deg, args.max_memory_mb
    )
    out = out_dir(args, args.design)
    check_writable_dir(out)
    from .common import Progress, want_progress

    bar = Progress(want_progress(args.progress))
    bar.start("heights")
    from ..export.sector_files import write_sector_files
    from ..report.sector import sector_summary_text
    from ..sector.run import run_sector

    res = run_sector(
        design, args.heights, args.assign, args.step_deg, args.tip_clearance_um, progress=lambda f, st: bar.set(f, st)
    )
    summ, _ = write_sector_files(res, args.design, out, stl=not args.no_stl)
    bar.set(1.0, "done")
    bar.close()
    if args.json:
        print(json_text(summ))
    else:
        print(sector_summary_text(design.drive.name, res, summ, out), end="")
    return EXIT_INTERFERENCE if res["audit_built"].has_tip_to_tip else EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    s = sub.add_parser(
        "sector",
        help="discrete-motion drive: sectored rigid gear, variable tooth heights, motion law, audit",
        epilog=epilog(one="teeth still meet tip to tip with the built heights"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s.add_argument("design", help="design file (TOML) with a [sectors] table, e.g. templates/d4_sectored.toml")
    s.add_argument("--out", help="output folder (default: output/<design name>)")
    s.add_argument("--progress", action="store_true", help="show the progress bar even when stderr is not a terminal")
    s.add_argument(
        "--heights",
        choices=("closed_form", "simulated", "full", "list"),
        default=None,
        help="which heights are built (default: [sectors] heights)",
    )
    s.add_argument(
        "--assign",
        choices=("register", "boundary"),
        default=None,
        help="closed form: how each tooth's generator angle is chosen (default: [sectors] assign)",
    )
    s.add_argument(
        "--step-deg",
        type=positive_float(0.0, 5.0, "deg"),
        default=None,
        help="generator-angle step of the sweeps (default 0.1)",
    )
    s.add_argument(
        "--tip-clearance-um",
        type=positive_float(-1e-12, 999.0, "um"),
        default=None,
        help="tip clearance the simulated heights keep (default: [sectors] tip_clearance_um)",
    )
    s.add_argument("--no-stl", action="store_true", help="skip the STL solid")
    s.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_memory_flag(s)
    s.set_defaults(func=cmd_sector)
