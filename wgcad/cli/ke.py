"""``wgcad ke``: kinematic error and lost motion of an imperfect drive, no load and under load, the installation-angle lever (docs/models.md 6.2, 6.3)."""

from __future__ import annotations

import json
from pathlib import Path

from wgcad.units import ARCSEC_PER_RAD

from .common import EXIT_OK, epilog, whole_number

__all__ = ["register", "cmd_ke"]

_AS = ARCSEC_PER_RAD


def cmd_ke(args) -> int:
    import math

    import numpy as np

    from ..accuracy import ke as K
    from ..atomic import atomic_batch, check_writable_dir
    from ..design import load_design
    from ..drive import build_drive
    from ..placement.imperfect import Imperfections, shortcuts

    if args.torque_nm is not None:
        _torques(args.torque_nm)  # bad torques are refused before any work
    design = load_design(args.design)
    drive = build_drive(design)
    imp = Imperfections.from_spec(design.imperfections)
    if args.torque_nm is not None:
        from ..design.load import require_bearing

        require_bearing(design)  # ... and a design the elastic model cannot build
    if args.plot:
        check_writable_dir(Path(args.plot).parent if str(Path(args.plot).parent) else Path("."))
    if args.json:
        check_writable_dir(Path(args.json).parent if str(Path(args.json).parent) else Path("."))
    from .common import Progress, want_progress

    # the steps' shares of D2's run (table 1.6 s, KE 0.2 s, the perfect parts' table 0.35 s)
    bar = Progress(want_progress(args.progress))
    bar.start("contact table")
    tab = K.contact_table(drive, imp, args.per_mesh, progress=lambda f: bar.set(0.7 * f, "contact table"))
    bar.set(0.7, "kinematic error")
    res = K.kinematic_error(drive, imp, table=tab)
    bar.set(0.8, "perfect parts")
    perfect = Imperfections()
    tab0 = tab if imp.cam_cam == 0.0 else K.contact_table(drive, perfect, args.per_mesh)
    intr = K.kinematic_error(drive, perfect, table=tab0, samples=args.per_mesh * drive.design.drive.z_rigid)
    orders, amp = K.spectrum(res)
    bar.set(1.0, "done")
    bar.close()
    d = design.drive
    expected = K.expected_orders(d.z_flex, d.z_rigid)
    top = np.argsort(amp)[::-1][:8]
    out = {
        "design": str(args.design),
        "engagement": res.engagement,
        "ke_pp_arcsec": round(res.ke_pp * _AS, 4),
        "intrinsic_ke_pp_arcsec": round(intr.ke_pp * _AS, 4),
        "lost_motion_arcsec": {
            "min": round(float(res.lost_motion.min()) * _AS, 4),
            "max": round(float(res.lost_motion.max()) * _AS, 4),
        },
        "samples": int(len(res.ke)),
        "per_mesh_period": args.per_mesh,
        "generator_turns": round(res.turns, 6),
        "shortcuts": shortcuts(imp),
        "expected_orders": expected,
        "spectrum_top": [
            {"order": round(float(orders[i]), 4), "amplitude_arcsec": round(float(amp[i]) * _AS, 4)} for i in top
        ],
    }
    print(f"{d.name}: no-load KE over one flexspline revolution ({res.turns:g} generator turns, {len(res.ke)} angles)")
    print(
        f"  engagement: {res.engagement}; lost motion {out['lost_motion_arcsec']['min']:.1f} .. {out['lost_motion_arcsec']['max']:.1f} arcsec"
    )
    print(
        f"  largest KE (peak to peak): {out['ke_pp_arcsec']:.2f} arcsec; perfect parts: {out['intrinsic_ke_pp_arcsec']:.3f} arcsec"
    )
    print(
        "  strongest orders: "
        + ", ".join(f"{s['order']:g} ({s['amplitude_arcsec']:.2f}'')" for s in out["spectrum_top"][:4])
    )
    out["deep_overlap_fraction"] = round(res.deep_overlap_fraction, 4)
    if res.deep_overlap_fraction > 0:
        print(
            f"  WARNING: at {100 * res.deep_overlap_fraction:.1f} % of the angles the first contact is a pair that overlaps "
            f"so deeply (turning back > {K.DEEP_OVERLAP * _AS:.0f} arcsec to separate) that the linear error model does not "
            "hold there: the KE can be off by hundreds of arcsec (docs/models.md 6.2); reduce the interference or use the elastic model"
        )
    if res.lost_motion.min() < 0:
        print(
            "  note: the teeth interfere (negative lost motion): the rigid-body position splits the interference; "
            "errors must stay well below the overlap for the linear model (docs/models.md 6.2) - under load use the elastic model"
        )
    sc = out["shortcuts"]
    print(
        f"  shortcuts that hold: mesh period {sc['mesh_period']}, identical waves {sc['identical_waves']}, mirror {sc['mirror_symmetry']} ({sc['why']})"
    )
    loaded = []
    if args.torque_nm is not None:
        loaded = _loaded(args, drive, imp, res, tab, out)
    scan = None
    if args.optimize_install_angle:
        best, best_pp, grid, pp = K.optimize_install_angle(tab, imp, "rigid")
        fpp = K.install_angle_scan(tab, imp, grid, "flex")
        scan = (np.degrees(grid), pp, math.degrees(best), best_pp, fpp)
        out["install_angle"] = {
            "best_rigid_angle_deg": round(math.degrees(best), 3),
            "best_ke_pp_arcsec": round(best_pp * _AS, 4),
            "angles_deg": [round(float(a), 3) for a in np.degrees(grid)],
            "rigid_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in pp],
            "flex_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in fpp],
        }
        print(
            f"  rigid gear installation angle: best {math.degrees(best):.2f} deg, largest KE {best_pp * _AS:.2f} arcsec "
            f"(range over angles {pp.min() * _AS:.2f} .. {pp.max() * _AS:.2f}); flexspline position: {fpp.min() * _AS:.2f} .. {fpp.max() * _AS:.2f}"
        )
    with atomic_batch() as batch:
        if args.json:
            Path(batch.temp_path(Path(args.json))).write_text(json.dumps(out, allow_nan=False, indent=2))
        if args.plot:
            from ..export.ke_figures import flank_png, install_png, ke_png

            stem = Path(args.plot)
            Path(batch.temp_path(stem.with_name(stem.name + "_ke.png"))).write_bytes(
                ke_png(f"{d.name}: kinematic error, no load", res, orders, amp, expected, intr)
            )
            if loaded:
                from ..export.ke_figures import ke_load_png

                Path(batch.temp_path(stem.with_name(stem.name + "_ke_load.png"))).write_bytes(
                    ke_load_png(
                        f"{d.name}: kinematic error under load (elastic model at whole mesh periods) and at no load",
                        res,
                        loaded,
                    )
                )
            if scan is not None:
                Path(batch.temp_path(stem.with_name(stem.name + "_install.png"))).write_bytes(
                    install_png(
                        f"{d.name}: largest KE against installation angle",
                        scan[0],
                        scan[1],
                        scan[2],
                        scan[3],
                        scan[0],
                        scan[4],
                    )
                )
            from ..accuracy.flank_errors import ENGAGEMENTS, drive_flank_errors
            from ..placement.imperfect import full_cycle_turns

            # [S2]'s model on the drive's own errors (docs/models.md 6.1) over the whole error cycle
            cyc = full_cycle_turns(d.z_flex, d.z_rigid)
            sgn = 1.0 if d.rotation == "ccw" else -1.0
            turns = np.linspace(0.0, cyc, 200 * cyc + 1)
            errs = {
                (zi, eng): drive_flank_errors(drive, imp, sgn * 2 * np.pi * turns, eng, zone=zone)
                for zi, zone in enumerate((0.0, np.pi))
                for eng in ENGAGEMENTS
            }
            Path(batch.temp_path(stem.with_name(stem.name + "_flank.png"))).write_bytes(
                flank_png(
                    f"{d.name}: mesh errors of [S2]'s model, from the design's errors (docs/models.md 6.1)", turns, errs
                )
            )
    return EXIT_OK


def _torques(text: str) -> list:
    from ..errors import DesignError
    from .load import torque_levels

    torques = torque_levels(text)
    if any(t <= 0 for t in torques):
        raise DesignError("--torque-nm", "the loaded KE needs torques > 0 N m (no load is the KE without the flag)")
    return torques


def _loaded(args, drive, imp, res, tab, out: dict) -> list:
    """The loaded KE at each ``--torque-nm`` (elastic model, docs/models.md 6.3): printed, added to ``out``, returned."""
    from ..accuracy.ke_load import loaded_ke
    from ..elastic import build_model
    from .common import Progress, want_progress

    torques = _torques(args.torque_nm)
    model = build_model(drive)  # a design without [bearing] data: a one-line DesignError naming it
    bar = Progress(want_progress(False))
    loaded = []
    out["loaded"] = []
    for T in torques:
        bar.start(f"{T:g} N m")
        L = loaded_ke(
            drive, imp, T, samples=args.load_samples, model=model, progress=lambda i, n: bar.set(i / n, f"{T:g} N m")
        )
        bar.close()
        idx = L.periods * tab.N
        nl = res.ke[idx] - res.ke[idx[0]]
        nl_pp = float(nl.max() - nl.min())
        loaded.append(L)
        out["loaded"].append(
            {
                "torque_nm": T,
                "ke_pp_arcsec": round(L.ke_pp * _AS, 4),
                "samples": int(len(L.ke)),
                "no_load_ke_pp_at_samples_arcsec": round(nl_pp * _AS, 4),
                "mean_wind_up_arcsec": round(L.wind_up * _AS, 3),
                "teeth_in_contact": [int(L.teeth_in_contact.min()), int(L.teeth_in_contact.max())],
                "seconds": round(L.seconds, 3),
            }
        )
        print(
            f"  under {T:g} N m (elastic model at {len(L.ke)} whole mesh periods over the revolution): largest KE "
            f"{L.ke_pp * _AS:.2f} arcsec against {nl_pp * _AS:.2f} at no load at the same angles; wind-up {L.wind_up * _AS:.1f} arcsec, "
            f"{L.teeth_in_contact.min()}-{L.teeth_in_contact.max()} tooth contacts"
        )
        if args.optimize_install_angle:
            import math

            import numpy as np

            from ..accuracy.ke_load import install_lever

            bar.start(f"installation angle, {T:g} N m")
            lev = install_lever(
                drive,
                imp,
                T,
                model=model,
                samples=args.load_samples,
                design=L,
                progress=lambda i, n: bar.set(i / n, f"installation angle, {T:g} N m"),
            )
            bar.close()
            out["loaded"][-1]["install_angle"] = {
                "best_rigid_angle_deg": round(math.degrees(lev.best_angle), 3),
                "best_ke_pp_arcsec": round(lev.best.ke_pp * _AS, 4),
                "design_angle_deg": round(math.degrees(imp.rigid_install), 3),
                "design_ke_pp_arcsec": round(lev.design.ke_pp * _AS, 4),
                "lever": round(lev.lever, 4),
                "angles_deg": [round(float(a), 3) for a in np.degrees(lev.grid)],
                "rigid_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in lev.grid_pp],
                "scan_samples": lev.scan_samples,
                "seconds": round(lev.seconds, 3),
            }
            print(
                f"    rigid gear installation angle under {T:g} N m: best {math.degrees(lev.best_angle):.1f} deg, largest KE "
                f"{lev.best.ke_pp * _AS:.2f} arcsec against {lev.design.ke_pp * _AS:.2f} at the design's "
                f"{math.degrees(imp.rigid_install):g} deg ({f'{lev.lever:.2f} times lower' if lev.lever > 1 else 'no angle does better'}; "
                f"scan of {len(lev.grid)} angles with "
                f"{lev.scan_samples} states each: {lev.grid_pp.min() * _AS:.1f} .. {lev.grid_pp.max() * _AS:.1f} arcsec)"
            )
    print(
        "  under load NOT CHECKED: the KE within a mesh period (the elastic model has states at whole mesh periods only)"
    )
    return loaded


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
    k.add_argument("--plot", help="PNG path stem: writes STEM_ke.png, STEM_flank.png (and STEM_install.png)")
    k.add_argument(
        "--per-mesh",
        type=whole_number(1, 512, "generator angles per mesh period"),
        default=16,
        help="generator angles per mesh period (default 16)",
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
