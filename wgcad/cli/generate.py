"""``wgcad generate``: DXF, STL, <design>.report.json and deformed-state pictures of a design."""

from __future__ import annotations

import argparse
import sys
import textwrap
import time

from ..design import load_design
from ..design.budget import RunShape
from ..drive import build_drive
from ..export.files.drive import write_drive_files
from ..export.formats.json_text import json_text
from ..extras import require
from ..report import format_summary
from .bounds import bounded
from .common import COMMAND_HELP, EXIT_OK, Progress, add_memory_flag, angles_deg, epilog, out_dir, want_progress
from .outputs import check_output_dir, write_stdout

__all__ = ["register", "cmd_generate"]


def cmd_generate(args) -> int:
    if args.generator_angle:
        require("plots", what="--generator-angle")  # the deformed assembly's picture
    t0 = time.perf_counter()
    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("loading modules")

    out = check_output_dir(out_dir(args, args.design))  # before any work
    bar.set(0.0, "reading the design")
    design = load_design(args.design)
    # the STL meshes dominate what the exports add (wgcad.design.budget)
    run = RunShape(exports=not args.no_stl)
    drive = build_drive(design, tol=args.chord_tol_um * 1e-3, max_memory_mb=args.max_memory_mb, run=run)
    res = write_drive_files(
        drive,
        args.design,
        out,
        angles_deg=args.generator_angle or [],
        stl=not args.no_stl,
        force=args.force,
        progress=bar.set,
    )
    bar.close()
    for name in res.kept:
        print(f"wgcad: warning: kept {out / name}: an earlier run wrote it, but it was changed since", file=sys.stderr)
    rep = res.report
    if args.json:
        write_stdout(json_text(rep) + "\n")
    elif not args.quiet:
        removed = f", removed {len(res.removed)} of the previous run's files" if res.removed else ""
        write_stdout(
            format_summary(rep)
            + "\n"
            + "".join(f"  NOT MODELLED: {n}\n" for n in rep["not_modelled"])
            + (f"  [imperfections]: {rep['imperfections']}\n" if "imperfections" in rep else "")
            + f"\n  wrote {len(res.files)} files to {out}/ ({res.files[-1].name}){removed} in "
            f"{time.perf_counter() - t0:.2f} s\n"
        )
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    g = sub.add_parser(
        "generate",
        help=COMMAND_HELP["generate"],
        description=textwrap.fill(
            "Write the manufacturing files of a design into one folder: <design>.dxf, "
            "<design>_flexspline.stl, <design>_rigid.stl, <design>.report.json and, per --generator-angle, "
            "<design>_phi<angle>.dxf/.png. Several designs can share a folder (each file starts with the design "
            "file's name). A re-run replaces this design's files and removes those of its previous run that it "
            "does not write again (listed in the hidden .<design>.wgcad-files.json), nothing else, "
            "and the temporary files a killed run left (.<file>.<pid>-<hex>.tmp).",
            width=79,
        ),
        epilog=epilog(five="the --generator-angle pictures need wgcad[plots]"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    g.add_argument(
        "--out", metavar="DIR", help="output folder (default: output/<design name>); created when the files are written"
    )
    g.add_argument(
        "--chord-tol-um",
        type=bounded("generate", "--chord-tol-um"),
        default=1.0,
        help="largest distance between outline and exact curve, um (default 1)",
    )
    g.add_argument(
        "--generator-angle",
        type=angles_deg,
        metavar="DEG[,DEG...]",
        help="also write the deformed assembly (DXF + PNG) at these generator angles, degrees",
    )
    g.add_argument("--no-stl", action="store_true", help="skip the STL solids (and the import of the 3D libraries)")
    g.add_argument(
        "--force",
        action="store_true",
        help="replace the files that a different design file of the same name wrote in --out",
    )
    g.add_argument(
        "--json",
        action="store_true",
        help="print the report (as in <design>.report.json) to stdout instead of the summary",
    )
    g.add_argument(
        "--progress",
        action="store_true",
        help="progress bar (fraction, ETA) on stderr even when it is not a terminal or with --quiet; "
        "by default it is drawn only on a terminal",
    )
    g.add_argument("--quiet", action="store_true", help="print nothing on success")
    add_memory_flag(g)
    g.set_defaults(func=cmd_generate)
