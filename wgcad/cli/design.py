"""``wgcad design``: from a requirements file to the drives that meet it (docs/models.md 14)."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from ..design.files import read_design_text
from ..errors import DesignError
from ..export.files.synthesis import write_search_files
from ..extras import require
from ..report.synthesis import summary_lines
from ..sweep.store import hold_folder
from ..synthesis.requirements import load_requirements
from ..synthesis.search import run_search
from .bounds import bounded
from .common import (
    COMMAND_HELP,
    EXIT_INTERFERENCE,
    EXIT_OK,
    Progress,
    epilog,
    scheduler_address,
    want_progress,
    whole_number,
)

__all__ = ["register", "cmd_design"]


def cmd_design(args) -> int:
    require("design", what="wgcad design")
    if args.scheduler and args.workers is not None:  # the rule of sweep's --workers
        raise DesignError(
            "--workers", "starts a local cluster; with --scheduler the scheduler's workers are used: give one of them"
        )
    workers = 0 if args.workers is None else args.workers
    if workers >= 1 or args.scheduler:
        require("sweep", what="--scheduler" if args.scheduler else "--workers")
    if not args.no_plots:
        require("plots", what="wgcad design (--no-plots draws none)")
    req = load_requirements(args.requirements)
    if args.trials is not None:
        req = replace(req, trials=args.trials)
    out = Path(args.out) if args.out else Path("output") / f"design_{Path(args.requirements).stem}"
    base_text = read_design_text(req.base)
    with hold_folder(out):  # one run at a time in a study folder: its journal and files stay one study's
        bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
        bar.start("candidates")
        res = run_search(
            req,
            out_dir=out,
            workers=workers,
            scheduler=args.scheduler,
            progress=lambda d, n: bar.set(d / n),
            explain=not args.no_explain,
        )
        bar.close()
        files = write_search_files(res, out, Path(args.requirements).stem, base_text, plot=not args.no_plots)
    if not args.quiet:
        lines = summary_lines(res)
        lines.append(f"  wrote {len(files)} files to {out}/ (and study.journal: run again with --out {out} to resume)")
        print("\n".join(lines))
    return EXIT_OK if res.best is not None else EXIT_INTERFERENCE


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    d = sub.add_parser(
        "design",
        help=COMMAND_HELP["design"],
        epilog=epilog(
            one="no candidate met every requirement (the summary says which one none met, and the closest)",
            five="the search needs wgcad[design], --workers/--scheduler wgcad[sweep], the picture wgcad[plots]",
            busy=True,
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Judges candidates cheapest check first (ratio, design rules, envelope, no-load audit, rating) and "
        "writes the best design as a commented design file, every candidate as CSV, the search's JSON and picture. "
        "Example: templates/requirements/d1_ratio100.toml",
    )
    d.add_argument("requirements", help="requirements file (TOML): [requirements] base, targets, limits; [free] keys")
    d.add_argument(
        "--workers",
        type=bounded("design", "--workers"),
        default=None,
        help="candidates judged at once, each in its own process of a local Dask cluster; 0: in this process, "
        "without Dask, one at a time (the default; as sweep --workers 0)",
    )
    d.add_argument(
        "--scheduler",
        type=scheduler_address,
        help="address of a running Dask scheduler, tcp://HOST:PORT (instead of a local one)",
    )
    d.add_argument(
        "--trials",
        type=whole_number(1, 10000, "trials"),
        default=None,
        help="candidates to judge in all (default the file's requirements.trials; resumed ones count)",
    )
    d.add_argument("--out", help="results folder (default output/design_REQNAME); reused to resume")
    d.add_argument(
        "--no-explain",
        action="store_true",
        help="do not judge the best design's neighbours (each free key moved a twentieth of its range each way, "
        "two more candidates per key) to say which requirement holds each chosen value",
    )
    d.add_argument("--no-plots", action="store_true", help="no PNG")
    d.add_argument("--progress", action="store_true", help="draw the progress bar even when stderr is not a terminal")
    d.add_argument("--quiet", action="store_true", help="no summary on stdout")
    d.set_defaults(func=cmd_design)
