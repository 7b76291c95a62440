"""``wgcad sector``: the sectored rigid gear of a discrete-motion drive: heights both ways, motion law, audit, DXF/STL."""

from __future__ import annotations

import argparse

from ..atomic import check_writable_dir
from ..design import load_design
from ..design.budget import check_sector_budget
from ..export.files.sector import write_sector_files
from ..export.formats.json_text import json_text
from ..extras import require
from ..report.sector import sector_summary_text
from ..sector.run import run_sector
from ..sector.scene import DEFAULT_STEP_DEG
from .bounds import bounded
from .common import (
    COMMAND_HELP,
    EXIT_INTERFERENCE,
    EXIT_OK,
    Progress,
    add_memory_flag,
    epilog,
    out_dir,
    want_progress,
)

__all__ = ["register", "cmd_sector"]


def cmd_sector(args) -> int:
    require("plots", what="wgcad sector")  # its heights, motion and audit pictures
    out = out_dir(args, args.design)
    check_writable_dir(out)  # before any work
    design = load_design(args.design)
    check_sector_budget(
        design.drive.z_flex, DEFAULT_STEP_DEG if args.step_deg is None else args.step_deg, args.max_memory_mb
    )

    bar = Progress(want_progress(args.progress))
    bar.start("heights")

    res = run_sector(
        design,
        args.heights,
        args.assign,
        args.step_deg,
        args.tip_clearance_um,
        progress=lambda f, st: bar.set(f, st),
        torque_nm=args.torque_nm,
        load=not args.no_load,
    )
    summ, _ = write_sector_files(res, args.design, out, stl=not args.no_stl)
    bar.set(1.0, "done")
    bar.close()
    if args.json:
        print(json_text(summ))
    else:
        print(sector_summary_text(design.drive.name, res, summ, out), end="")
    return EXIT_INTERFERENCE if res["audit_built"].interferes else EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    s = sub.add_parser(
        "sector",
        help=COMMAND_HELP["sector"],
        epilog=epilog(
            one="with the built heights teeth still meet tip to tip or interfere at the flanks",
            five="the pictures need wgcad[plots]",
        ),
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
        choices=("boundary", "register"),
        default=None,
        help="closed form: how each tooth's generator angle is chosen (default: [sectors] assign)",
    )
    s.add_argument(
        "--step-deg",
        type=bounded("sector", "--step-deg"),
        default=None,
        help="generator-angle step of the sweeps (default 0.1)",
    )
    s.add_argument(
        "--tip-clearance-um",
        type=bounded("sector", "--tip-clearance-um"),
        default=None,
        help="tip clearance the simulated heights keep (default: [sectors] tip_clearance_um)",
    )
    s.add_argument(
        "--torque-nm",
        type=bounded("sector", "--torque-nm"),
        default=None,
        help="torque of the transitions under load (default: [load] rated_torque_nm; needs [material] and [bearing])",
    )
    s.add_argument("--no-load", action="store_true", help="skip the transitions under load")
    s.add_argument("--no-stl", action="store_true", help="skip the STL solid")
    s.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_memory_flag(s)
    s.set_defaults(func=cmd_sector)
