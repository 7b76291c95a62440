"""``wgcad ke``: kinematic error and lost motion of an imperfect drive, no load and under load, the installation-angle lever (docs/models.md 6.2, 6.3)."""

from __future__ import annotations

from pathlib import Path

from wgcad.units import ARCSEC_PER_RAD

from ..export.json_text import json_text
from .common import EXIT_OK, epilog, positive_float, whole_number

__all__ = ["register", "cmd_ke"]

_AS = ARCSEC_PER_RAD


def cmd_ke(args) -> int:

    from ..atomic import atomic_batch, check_writable_dir
    from ..design import load_design
    from ..drive import build_drive
    from ..placement.imperfect import Imperfections

    if args.torque_nm is not None:
        _torques(args.torque_nm)  # bad torques are refused before any work
    design = load_design(args.design)
    drive = build_drive(design, tol=args.chord_tol_um * 1e-3)
    imp = Imperfections.from_spec(design.imperfections)
    if args.torque_nm is not None:
        from ..design.load import require_bearing

        require_bearing(design)  # ... and a design the elastic model cannot build
    if args.plot:
        check_writable_dir(Path(args.plot).parent if str(Path(args.plot).parent) else Path("."))
    if args.json:
        check_writable_dir(Path(args.json).parent if str(Path(args.json).parent) else Path("."))
    if args.html:
        from .outputs import STDOUT, check_output_file

        if args.html == STDOUT:
            from ..errors import OutputError

            raise OutputError("--html: writes a page, so it needs a path, not - (standard output)")
        check_output_file(args.html, flag="--html", inputs=[args.design])
    from ..report.ke_run import add_install_scan, add_loaded, no_load
    from .common import Progress, want_progress

    bar = Progress(want_progress(args.progress))
    bar.start("contact table")
    run, lines = no_load(drive, imp, args.per_mesh, str(args.design), progress=lambda f, st: bar.set(f, st))
    bar.close()
    print("\n".join(lines))
    if args.torque_nm is not None:
        lines = add_loaded(
            run,
            _torques(args.torque_nm),
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
            from ..export.ke_html import ke_html

            Path(batch.temp_path(Path(args.html))).write_text(ke_html(run), encoding="utf-8")
        if args.plot:
            from ..export.ke_figures import ke_pngs

            stem = Path(args.plot)
            for suffix, png in ke_pngs(run).items():
                Path(batch.temp_path(stem.with_name(stem.name + suffix + ".png"))).write_bytes(png)
    return EXIT_OK


def _torques(text: str) -> list:
    from ..errors import DesignError
    from .load import torque_levels

    torques = torque_levels(text)
    if any(t <= 0 for t in torques):
        raise DesignError("--torque-nm", "the loaded KE needs torques > 0 N m (no load is the KE without the flag)")
    return torques


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    k = sub.add_parser(
        "ke",
        help="no-load kinematic error, lost motion and the installation-angle lever of an imperfect drive",
        epilog=epilog(model="teeth that never touch; with --torque-nm the elastic model"),
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
        type=positive_float(0.0, 100.0, "um"),
        default=1.0,
        help="largest distance between the teeth's outlines and their exact curves, um (default 1; D2's KE reads "
        "0.8 arcsec higher at 0.025: docs/models.md 6.2)",
    )
    k.add_argument(
        "--torque-nm",
        metavar="T",
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
