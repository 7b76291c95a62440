"""``wgcad design``: from a requirements file to the drives that meet it (docs/models.md 14)."""

from __future__ import annotations

from pathlib import Path

from .common import EXIT_INTERFERENCE, EXIT_OK, epilog

__all__ = ["register", "cmd_design"]


def cmd_design(args) -> int:
    from ..atomic import ensure_writable_dir
    from ..design.files import read_design_text
    from ..export.synthesis_files import write_search_files
    from ..report.synthesis import summary_lines
    from ..synthesis.requirements import load_requirements
    from ..synthesis.search import run_search
    from .common import Progress, want_progress

    req = load_requirements(args.requirements)
    if args.trials is not None:
        from dataclasses import replace

        req = replace(req, trials=args.trials)
    out = Path(args.out) if args.out else Path("output") / f"design_{Path(args.requirements).stem}"
    base_text = read_design_text(req.base)
    ensure_writable_dir(out)
    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    bar.start("candidates")
    res = run_search(
        req,
        out_dir=out,
        workers=args.workers,
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
    import argparse

    from .sweep import _count, _scheduler

    d = sub.add_parser(
        "design",
        help="search the free keys of a requirements file for drives that meet it; resumable, on Dask",
        epilog=epilog(one="no candidate met every requirement (the summary says which one none met, and the closest)"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Judges candidates cheapest check first (ratio, design rules, envelope, no-load audit, rating) and "
        "writes the best design as a commented design file, every candidate as CSV, the search's JSON and picture. "
        "Example: templates/requirements/d1_ratio100.toml",
    )
    d.add_argument("requirements", help="requirements file (TOML): [requirements] base, targets, limits; [free] keys")
    d.add_argument(
        "--workers",
        type=_count(1, 4096, "worker processes"),
        default=1,
        help="candidates judged at once, each in its own process of a local Dask cluster (default 1: this process)",
    )
    d.add_argument(
        "--scheduler",
        type=_scheduler,
        help="address of a running Dask scheduler, tcp://HOST:PORT (instead of a local one)",
    )
    d.add_argument(
        "--trials",
        type=_count(1, 10000, "trials"),
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
