"""``wgcad ke``: kinematic error and lost motion of an imperfect drive, no load and under load, the installation-angle lever (docs/models.md 6.2, 6.3)."""

from __future__ import annotations

import argparse
from pathlib import Path

from wgcad.units import ARCSEC_PER_RAD

from ..atomic import atomic_batch, check_writable_dir
from ..design import load_design
from ..design.load import require_bearing
from ..drive import build_drive
from ..errors import DesignError, OutputError
from ..export.formats.json_text import json_text
from ..export.pages.ke import ke_html
from ..export.pictures.ke import ke_pngs
from ..placement.imperfect import Imperfections
from ..services.ke import add_install_scan, add_loaded, no_load
from .bounds import bounded
from .common import (
    COMMAND_HELP,
    EXIT_OK,
    Progress,
    epilog,
    flag_value,
    require_picture_extras,
    want_progress,
    whole_number,
)
from .load import torque_levels
from .outputs import STDOUT, check_output_file

__all__ = ["register", "cmd_ke"]

_AS = ARCSEC_PER_RAD


def cmd_ke(args) -> int:
    require_picture_extras(args)

    # the output paths are judged before any work (the gears are built next)
    if args.plot:
        check_writable_dir(Path(args.plot).parent if str(Path(args.plot).parent) else Path("."))
    if args.json:
        check_writable_dir(Path(args.json).parent if str(Path(args.json).parent) else Path("."))
    if args.html:
        if args.html == STDOUT:
            raise OutputError("--html: writes a page, so it needs a path, not - (standard output)")
        check_output_file(args.html, flag="--html", inputs=[args.design])
    design = load_design(args.design)
    if args.torque_nm is not None:
        require_bearing(design)  # a design the elastic model cannot build is refused before any work
    drive = build_drive(design, tol=args.chord_tol_um * 1e-3)
    imp = Imperfections.from_spec(design.imperfections)

    bar = Progress(want_progress(args.progress))
    bar.start("contact table")
    run, lines = no_load(drive, imp, args.per_mesh, str(args.design), progress=lambda f, st: bar.set(f, st))
    bar.close()
    print("\n".join(lines))
    if args.torque_nm is not None:
        lines = add_loaded(
            run,
            args.torque_nm,
            samples=args.load_samples,
            install=args.optimize_install_angle,
            bar=Progress(want_progress(False)),
        )
        print("\n".join(lines))
    if args.optimize_install_angle:
        print("\n".join(add_install_scan(run)))
    with atomic_batch() as batch:
        if args.json:
            Path(batch.temp_path(Path(args.json))).write_text(json_text(run.doc))
        if args.html:
            Path(batch.temp_path(Path(args.html))).write_text(ke_html(run), encoding="utf-8")
        if args.plot:
            stem = Path(args.plot)
            for suffix, png in ke_pngs(run).items():
                Path(batch.temp_path(stem.with_name(stem.name + suffix + ".png"))).write_bytes(png)
    return EXIT_OK


def _torques(text: str) -> list:
    """The ``--torque-nm`` type of ``ke``: torque levels (:func:`wgcad.cli.load.torque_levels`), each > 0, judged
    while the line is parsed."""

    def parse(t: str) -> list:
        torques = torque_levels(t)
        if any(v <= 0 for v in torques):
            raise DesignError("--torque-nm", "the loaded KE needs torques > 0 N m (no load is the KE without the flag)")
        return torques

    return flag_value(parse, text)


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    k = sub.add_parser(
        "ke",
        help=COMMAND_HELP["ke"],
        epilog=epilog(
            model="teeth that never touch; with --torque-nm the elastic model",
            five="--plot needs wgcad[plots], --html wgcad[html]",
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    k.add_argument(
        "design", help="design file (TOML) with an optional [imperfections] table, e.g. templates/d2_imperfect.toml"
    )
    k.add_argument(
        "--optimize-install-angle",
        action="store_true",
        help="scan the rigid gear's installation angle (36 angles, then finer) and the flexspline's position",
    )
    k.add_argument("--json", help="write the figures as JSON here")
    k.add_argument("--html", help="write one self-contained interactive page (zoomable figures, the tables) here")
    k.add_argument("--plot", help="PNG path stem: writes STEM_ke.png, STEM_flank.png (and STEM_install.png)")
    k.add_argument(
        "--per-mesh",
        type=whole_number(1, 512, "generator angles per mesh period"),
        default=16,
        help="generator angles per mesh period (default 16)",
    )
    k.add_argument(
        "--chord-tol-um",
        type=bounded("ke", "--chord-tol-um"),
        default=1.0,
        help="largest distance between the teeth's outlines and their exact curves, um (default 1; D2's KE reads "
        "0.8 arcsec higher at 0.025: docs/models.md 6.2)",
    )
    k.add_argument(
        "--torque-nm",
        metavar="T",
        type=_torques,
        help="also the KE under these output torques (a value, a list or START:STOP:STEP, "
        "N m > 0) from the elastic model (needs [bearing]); STEM_ke_load.png with --plot",
    )
    k.add_argument(
        "--load-samples",
        type=whole_number(2, 100_000, "load states"),
        default=None,
        metavar="N",
        help="load states over the flexspline revolution, at whole mesh periods (default 4 |u_hg| + 4)",
    )
    k.add_argument("--progress", action="store_true", help="show the progress bar even when stderr is not a terminal")
    k.set_defaults(func=cmd_ke)
