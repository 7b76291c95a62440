"""``wgcad audit DESIGN --torque-nm ...``: the drive under load (elastic contact model, docs/models.md 4.1)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..atomic import atomic_batch, check_writable_dir
from ..constants import MAX_LOAD_LEVELS
from ..design import load_design
from ..design.budget import check_load_budget
from ..errors import DesignError
from ..export.formats.json_text import json_text
from ..export.pages.load import load_html
from ..export.pictures.load import entry_gap_png, force_distribution_png
from ..numbers import read_values
from .bounds import REVERSE
from .common import EXIT_INTERFERENCE, EXIT_OK, Progress, flag_value, key_float

__all__ = ["register_args", "run_load", "torque_levels", "torque_flag", "RATED", "RATED_STEPS"]

#: ``--torque-nm`` without a value: the design's rated torque, from zero in RATED_STEPS steps
RATED = "rated"
RATED_STEPS = 12


def torque_levels(text: str) -> list[float]:
    """``"0:3000:250"`` (start:stop:step, stop included), ``"500"`` or ``"0,500,1000"`` -> torques in N m (>= 0), at
    most :data:`~wgcad.constants.MAX_LOAD_LEVELS` of them (:func:`wgcad.numbers.read_values`)."""
    values = read_values("--torque-nm", text, what="torques", unit="N m", max_count=MAX_LOAD_LEVELS)
    for v in values:
        if v < 0:  # judged here, not by read_values' bound, to say why a sign is refused
            raise DesignError("--torque-nm", f"torques must be >= 0 N m, got {v:g}: {REVERSE}")
    return values


def torque_flag(text: str):
    """The ``--torque-nm`` type (``audit`` and ``ke``): :func:`torque_levels`, judged while the line is parsed (before
    the design is read); the flag alone (its ``const``) stays :data:`RATED`."""
    if text == RATED:
        return RATED
    return flag_value(torque_levels, text)


def register_args(a) -> None:
    """Add the load flags to the ``audit`` subparser."""
    g = a.add_argument_group("under load (elastic contact model; needs [bearing] in the design)")
    g.add_argument(
        "--torque-nm",
        metavar="SPEC",
        nargs="?",
        const=RATED,
        type=torque_flag,
        help="output torques: START:STOP:STEP (e.g. 0:3000:250), a value or a list; without SPEC, 0 to the "
        "design's [load] rated_torque_nm in 12 steps; exit 1 when the entry gap Delta closes at a requested load",
    )
    g.add_argument(
        "--cam-offset-um",
        type=key_float("load", "cam_offset_um"),
        default=None,
        help="cam axis offset e_h, um (default: [load] of the design, else 0)",
    )
    g.add_argument(
        "--cam-offset-deg",
        type=key_float("load", "cam_offset_deg"),
        default=None,
        help="direction of e_h from the major axis, deg (default: [load], else 0)",
    )
    g.add_argument(
        "--compare",
        metavar="DESIGN2",
        help="also sweep DESIGN2 and plot both designs' entry gap against torque "
        "for e_h = 0 and the given offset (40 um if none): PATH_compare.png",
    )


def _levels(args) -> list[float]:
    """The torque levels of ``--torque-nm``: as given, or 0 to ``[load] rated_torque_nm`` in :data:`RATED_STEPS` steps."""
    if args.torque_nm != RATED:
        return args.torque_nm

    rated = load_design(args.design).load.rated_torque_nm
    if rated is None or not rated > 0:
        raise DesignError(
            "load.rated_torque_nm",
            "--torque-nm without a value sweeps 0 to the rated torque: give "
            "[load] rated_torque_nm > 0 in the design or a SPEC to the flag",
        )
    return [rated * i / RATED_STEPS for i in range(RATED_STEPS + 1)]


def run_load(args) -> int:
    """The load audit: sweep, print, write JSON and PNGs atomically; exit 1 when the entry gap closes."""
    from ..report.load import load_lines, load_run

    torques = _levels(args)
    # every level's solved state is held to the end: judged against the budget before the first is solved
    z_flex = load_design(args.design).drive.z_flex
    check_load_budget(len(torques), z_flex, args.sections, args.max_memory_mb, sweeps=2 if args.compare else 1)
    for path in (args.json, args.plot, args.html):
        if path:
            check_writable_dir(Path(path).parent if str(Path(path).parent) else Path("."))
    prog = Progress(args.progress or sys.stderr.isatty())
    drive, res = load_run(args.design, torques, args.cam_offset_um, args.cam_offset_deg, args.sections, prog)
    compare = None
    if args.compare:
        e = args.cam_offset_um if args.cam_offset_um else 40.0
        compare = []
        for path in (args.design, args.compare):
            for eu in (0.0, e):
                d2, r2 = load_run(path, torques, eu, args.cam_offset_deg or 0.0, args.sections, prog)
                compare.append(
                    {
                        "label": f"{d2.design.drive.name}, e_h = {eu:g} um",
                        "torque_nm": [lv["torque_nm"] for lv in r2["levels"]],
                        "entry_gap_um": [lv["entry_gap_um"] for lv in r2["levels"]],
                    }
                )
        res["compare"] = compare
    with atomic_batch() as batch:
        if args.json:
            Path(batch.temp_path(args.json)).write_text(json_text(res) + "\n")
        if args.html:
            Path(batch.temp_path(args.html)).write_text(load_html(res), encoding="utf-8")
        if args.plot:
            p = Path(args.plot)
            name = res["design"]
            series = [
                {
                    "label": f"{name}, e_h = {res['cam_offset_um']:g} um",
                    "torque_nm": [lv["torque_nm"] for lv in res["levels"]],
                    "entry_gap_um": [lv["entry_gap_um"] for lv in res["levels"]],
                }
            ]
            Path(batch.temp_path(p.with_name(f"{p.stem}_entry_gap.png"))).write_bytes(
                entry_gap_png(
                    series,
                    f"{name}: entry gap against output torque (smallest over waves and sections)",
                    res["interference_tol_um"],
                )
            )
            Path(batch.temp_path(p.with_name(f"{p.stem}_forces.png"))).write_bytes(
                force_distribution_png(
                    res["levels"], f"{name}: tooth forces (all sections) and ball loads around the rim"
                )
            )
            if compare:
                Path(batch.temp_path(p.with_name(f"{p.stem}_compare.png"))).write_bytes(
                    entry_gap_png(
                        compare,
                        "entry gap against output torque: tooth forms and cam offsets",
                        res["interference_tol_um"],
                    )
                )
    if not args.quiet:
        print(load_lines(res["design"], res))
        for c in compare or []:
            print(
                "  compare "
                + c["label"]
                + ": entry gap um "
                + ", ".join("none" if g is None else f"{g:.2f}" for g in c["entry_gap_um"])
            )
    return EXIT_INTERFERENCE if res["entry_gap_closes"] else EXIT_OK
