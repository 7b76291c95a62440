"""``wgcad sweep``: a tolerance Monte Carlo or a design study over a sweep spec, on Dask (local cluster or a scheduler), resumable."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import atomic_batch, check_writable_dir
from ..errors import DesignError, OutputError
from ..errors import OutputError as _OutputError
from ..export.formats.json_text import json_text
from ..export.pages.sweep import sweep_html
from ..export.pictures.sweep import sweep_pngs
from ..extras import require
from ..sweep.runner import run_sweep
from ..sweep.sampling import chunk_check
from ..sweep.spec import load_spec
from ..sweep.store import Store, hold_folder
from ..sweep.summary import format_summary, summarize
from ..sweep.tasks import columns_of
from .bounds import bounded
from .common import COMMAND_HELP, EXIT_OK, Progress, epilog, scheduler_address, want_progress, whole_number
from .outputs import STDOUT, check_output_file

__all__ = ["register", "cmd_sweep"]


def cmd_sweep(args) -> int:
    if args.scheduler and args.workers is not None:
        raise DesignError(
            "--workers", "starts a local cluster; with --scheduler the scheduler's workers are used: give one of them"
        )
    if not args.summary_only and args.workers != 0:
        require("sweep", what="wgcad sweep")
    if not args.no_plots:
        require("plots", what="wgcad sweep (--no-plots writes none)")
    if args.html:
        require("html", what="--html")
    spec = load_spec(args.spec)
    out = Path(args.out) if args.out else Path("output") / f"sweep_{Path(args.spec).stem}"
    check_writable_dir(out)
    if args.html:
        if args.html == STDOUT:
            raise _OutputError("--html: writes a page, so it needs a path, not - (standard output)")
        check_output_file(args.html, flag="--html", inputs=[args.spec])
    if args.summary_only and not (out / "sweep.json").is_file():
        raise OutputError(f"--summary-only: {out} holds no sweep results (no sweep.json)")
    with hold_folder(out):  # one run at a time in a sweep folder: its chunks and summary stay one sweep's
        bar = Progress(want_progress(args.progress) and not args.quiet)
        bar.start("starting the cluster")
        info = None
        if not args.summary_only:
            info = run_sweep(spec, out, scheduler=args.scheduler, workers=args.workers, batch=args.batch, progress=bar)
        payload = spec.payload()
        store = Store(out, payload["fingerprint"], columns_of(payload), spec.total, name=spec.name)
        if args.summary_only:
            store.open()
        bar.set(1.0, "summary")
        cols = store.read(check=chunk_check(payload))
        summ = summarize(spec, cols)
        if info is not None:
            summ["run"] = {k: v for k, v in info.__dict__.items()}
        summ["results"] = {"folder": str(out), "format": store.fmt, "chunks": len(store.done_ranges())}
        with atomic_batch() as batch:
            Path(batch.temp_path(out / "summary.json")).write_text(json_text(summ, default=str) + "\n")
            if not args.no_plots and len(cols["sample"]):
                for name, png in sweep_pngs(spec, cols, summ).items():
                    Path(batch.temp_path(out / name)).write_bytes(png)
            if args.html and len(cols["sample"]):
                Path(batch.temp_path(Path(args.html))).write_text(sweep_html(spec, cols, summ), encoding="utf-8")
        bar.close()
    if not args.quiet:
        print(format_summary(summ, info))
        print(
            f"  results: {out}/chunks ({store.fmt}), {out}/summary.json" + ("" if args.no_plots else f", {out}/*.png")
        )
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    s = sub.add_parser(
        "sweep",
        help=COMMAND_HELP["sweep"],
        epilog=epilog(
            four="the Dask cluster failed (a worker died, the scheduler went away): the chunks done are kept, "
            "run again to resume",
            five="the cluster needs wgcad[sweep], the pictures wgcad[plots] (--no-plots: none), --html wgcad[html]",
            busy=True,
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Runs every sample of SPEC not yet stored in --out (rerun after an interruption: only "
        "the missing samples are computed). Example spec: templates/sweeps/d2_tolerance_sweep.toml",
    )
    s.add_argument(
        "spec",
        help="sweep spec (TOML): [sweep] design, samples, seed; [parameters.TABLE.KEY]; [figures] record; [limits]",
    )
    s.add_argument(
        "--scheduler",
        type=scheduler_address,
        help="address of a running Dask scheduler, tcp://HOST:PORT (default: a local cluster)",
    )
    s.add_argument(
        "--workers",
        type=bounded("sweep", "--workers"),
        default=None,
        help="worker processes of the local cluster (default: one per core); 0: in this process, without Dask "
        "(as design --workers 0)",
    )
    s.add_argument(
        "--batch",
        type=whole_number(1, 1_000_000, "samples per task"),
        default=None,
        help="samples per task (default: the spec's sweep.batch, else chosen by measuring a probe task)",
    )
    s.add_argument("--out", help="results folder (default output/sweep_SPECNAME); reused to resume")
    s.add_argument("--summary-only", action="store_true", help="compute nothing: summarise the samples stored in --out")
    s.add_argument("--no-plots", action="store_true", help="no PNGs")
    s.add_argument("--html", help="write one self-contained interactive page (zoomable figures, the tables) here")
    s.add_argument("--progress", action="store_true", help="draw the progress bar even when stderr is not a terminal")
    s.add_argument("--quiet", action="store_true", help="no summary on stdout")
    s.set_defaults(func=cmd_sweep)
