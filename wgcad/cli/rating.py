"""``wgcad rating``: the catalogue-style datasheet of a drive: rated torque and what binds it, stresses, stiffness, lost motion, ratcheting, bearing life (docs/models.md 10)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..atomic import atomic_batch
from ..design import load_design
from ..drive import build_drive
from ..errors import OutputError
from ..export.formats.json_text import json_text
from ..export.pages.rating import rating_html
from ..export.pictures.rating import rating_png
from .bounds import bounded
from .common import (
    COMMAND_HELP,
    EXIT_INTERFERENCE,
    EXIT_OK,
    Progress,
    epilog,
    key_float,
    require_picture_extras,
    want_progress,
)
from .outputs import STDOUT, check_output_file

__all__ = ["register", "cmd_rating"]


def cmd_rating(args) -> int:
    require_picture_extras(args)
    from ..rating.datasheet import rate_drive
    from ..report.rating import rating_document, rating_lines

    for flag, path in (("--json", args.json), ("--plot", args.plot), ("--html", args.html)):
        if path == STDOUT:
            raise OutputError(f"{flag}: writes a file, so it needs a path, not - (standard output)")
        if path:
            check_output_file(path, flag=flag, inputs=[args.design])
    design = load_design(args.design)
    drive = build_drive(design)
    bar = Progress(want_progress(args.progress))
    bar.start("torque levels")
    ld = design.load
    offset = (
        ld.cam_offset_um if args.cam_offset_um is None else args.cam_offset_um,
        ld.cam_offset_deg if args.cam_offset_deg is None else args.cam_offset_deg,
    )
    ds = rate_drive(drive, speed_rpm=args.speed_rpm, sections=args.sections, progress=bar.set, cam_offset=offset)
    bar.close()
    print("\n".join(rating_lines(ds)))
    with atomic_batch() as batch:
        if args.json:
            doc = rating_document(ds, str(args.design))
            Path(batch.temp_path(Path(args.json))).write_text(json_text(doc))
        if args.plot:
            Path(batch.temp_path(Path(args.plot))).write_bytes(rating_png(ds))
        if args.html:
            Path(batch.temp_path(Path(args.html))).write_text(rating_html(ds), encoding="utf-8")
    return EXIT_OK if ds.rated_torque_nm > 0 else EXIT_INTERFERENCE


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    r = sub.add_parser(
        "rating",
        help=COMMAND_HELP["rating"],
        epilog=epilog(
            one="no rated torque: a criterion fails at no load (the datasheet says which)",
            model="the elastic model cannot solve the unloaded drive",
            five="--plot needs wgcad[plots], --html wgcad[html]",
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    r.add_argument(
        "design",
        help="design file (TOML) with [bearing] and [material] ultimate_strength_mpa, e.g. templates/d1_involute.toml",
    )
    r.add_argument(
        "--speed-rpm",
        type=bounded("rating", "--speed-rpm"),
        default=None,
        help="input speed the bearing life is rated at (default [load] input_speed_rpm, 2000)",
    )
    r.add_argument(
        "--cam-offset-um",
        type=key_float("load", "cam_offset_um"),
        default=None,
        help="radial offset of the cam axis the drive is rated with (default [load] cam_offset_um); the ratcheting "
        "torque is also given without it",
    )
    r.add_argument(
        "--cam-offset-deg",
        type=key_float("load", "cam_offset_deg"),
        default=None,
        help="direction of the offset from the major axis (default [load] cam_offset_deg)",
    )
    r.add_argument(
        "--sections",
        type=bounded("rating", "--sections"),
        default=3,
        help="cross-sections of the elastic model over the face width (default 3)",
    )
    r.add_argument("--json", help="write the datasheet as JSON here")
    r.add_argument("--plot", help="write the datasheet's picture (PNG) here")
    r.add_argument("--html", help="write the datasheet as one self-contained interactive page here")
    r.add_argument("--progress", action="store_true", help="show the progress bar even when stderr is not a terminal")
    r.set_defaults(func=cmd_rating)
