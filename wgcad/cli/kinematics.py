"""``wgcad kinematics``: gear ratios, mesh period, and the external ring generator's velocities."""

from __future__ import annotations

from pathlib import Path

from .common import EXIT_OK, epilog, out_dir, positive_float

__all__ = ["register", "cmd_kinematics"]


def cmd_kinematics(args) -> int:
    import numpy as np

    from ..design import load_design
    from ..drive import build_drive
    from ..kinematics import gear_ratios

    design = load_design(args.design)
    drive = build_drive(design)
    if design.external:  # judge the output folder before printing anything
        from .outputs import check_output_dir

        check_output_dir(out_dir(args, args.design))
    d = design.drive
    r = gear_ratios(d.z_flex, d.z_rigid)

    def sense(u):
        return "same direction as the generator" if u > 0 else "opposite to the generator"

    print(f"{d.name}")
    print(f"  rigid gear fixed:      u_hg = {r['u_hg']:g}  (flexspline turns {sense(r['u_hg'])})")
    print(f"  flexspline fixed:      u_hb = {r['u_hb']:g}  (rigid gear turns {sense(r['u_hb'])})")
    z_ref = d.z_rigid if d.fixed == "rigid" else d.z_flex
    print(
        f"  mesh period (perfect gears): {360.0 / z_ref:.6g} deg of generator rotation "
        f"(the {'rigid' if d.fixed == 'rigid' else 'flexspline'} teeth pass one pitch)"
    )
    if not design.external:
        return EXIT_OK
    from ..atomic import atomic_batch
    from ..kinematics import ring_generator_velocities

    out = out_dir(args, args.design)  # checked above; created with the files
    a_w = design.w0 if args.eccentricity is None else args.eccentricity
    phi = np.linspace(0.0, np.pi, 721)
    vel = ring_generator_velocities(drive.law, phi, args.omega_h, design.flexspline.rim_thickness, a_w)
    cols = ["V_w", "V_v", "dtheta_dt", "V_wK", "V_vK", "V_d", "V_dw", "V_dv", "V_sl"]
    units = {"dtheta_dt": "rad_s"}
    header = "phi_deg," + ",".join(f"{c}_{units.get(c, 'mm_s')}" for c in cols)
    rows = np.column_stack([np.rad2deg(phi)] + [getattr(vel, c) for c in cols])
    import io

    buf = io.StringIO()
    np.savetxt(buf, rows, delimiter=",", header=header, comments="", fmt="%.9g")
    from ..export.figures import velocities_png

    png = velocities_png(
        vel, f"{d.name}: external ring generator velocities, omega_h = {args.omega_h:g} rad/s, a_w = {a_w:.3f} mm"
    )
    stem = Path(args.design).stem
    with atomic_batch() as batch:
        Path(batch.temp_path(out / f"{stem}_velocities.csv")).write_text(buf.getvalue())
        Path(batch.temp_path(out / f"{stem}_velocities.png")).write_bytes(png)
    i = int(np.argmax(np.abs(vel.V_sl)))
    print(f"  external ring generator, omega_h = {args.omega_h:g} rad/s, a_w = {a_w:.4f} mm:")
    print(
        f"    washer speed V_d = {vel.V_d[0]:.4g} mm/s; largest sliding speed |V_sl| = {abs(vel.V_sl[i]):.4g} mm/s at phi = {np.rad2deg(phi[i]):.1f} deg"
    )
    print(f"  wrote {stem}_velocities.csv and .png to {out}/")
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    k = sub.add_parser(
        "kinematics",
        help="gear ratios; velocities of the external ring generator (CSV + PNG)",
        epilog=epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    k.add_argument("design", help="design file (TOML), e.g. templates/d3_external.toml")
    k.add_argument(
        "--out",
        metavar="DIR",
        help="output folder of the velocity CSV and PNG (external deformation only; default: output/<design name>)",
    )
    k.add_argument(
        "--omega-h",
        type=positive_float(0.0, 1e6, "rad/s"),
        default=1.0,
        help="generator speed, rad/s (default 1: velocities per rad/s; [S3] uses 210)",
    )
    k.add_argument(
        "--eccentricity",
        type=positive_float(0.0, 100.0, "mm"),
        default=None,
        help="washer crank eccentricity a_w, mm (default W0)",
    )
    k.set_defaults(func=cmd_kinematics)
