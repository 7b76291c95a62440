"""``wgcad kinematics``: gear ratios, mesh period, and the external ring generator's velocities."""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import numpy as np

from ..atomic import atomic_batch
from ..design import load_design
from ..drive import build_drive
from ..errors import DesignError
from ..export.pictures.drive import velocities_png
from ..extras import require
from ..kinematics import gear_ratios, ring_generator_velocities
from .bounds import bounded
from .common import COMMAND_HELP, EXIT_OK, epilog, out_dir
from .outputs import check_output_dir

__all__ = ["register", "cmd_kinematics", "DEFAULT_OMEGA_H"]

#: --omega-h by default: velocities per rad/s of the generator
DEFAULT_OMEGA_H = 1.0


def cmd_kinematics(args) -> int:
    require("plots", what="wgcad kinematics")  # its velocities picture
    design = load_design(args.design)
    if not design.external:
        _refuse_velocity_flags(args, design)
    else:  # judge the output folder before any work
        check_output_dir(out_dir(args, args.design))
    drive = build_drive(design)
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

    out = out_dir(args, args.design)  # checked above; created with the files
    a_w = design.w0 if args.eccentricity is None else args.eccentricity
    omega_h = DEFAULT_OMEGA_H if args.omega_h is None else args.omega_h
    phi = np.linspace(0.0, np.pi, 721)
    vel = ring_generator_velocities(drive.law, phi, omega_h, design.flexspline.rim_thickness, a_w)
    cols = ["V_w", "V_v", "dtheta_dt", "V_wK", "V_vK", "V_d", "V_dw", "V_dv", "V_sl"]
    units = {"dtheta_dt": "rad_s"}
    header = "phi_deg," + ",".join(f"{c}_{units.get(c, 'mm_s')}" for c in cols)
    rows = np.column_stack([np.rad2deg(phi)] + [getattr(vel, c) for c in cols])

    buf = io.StringIO()
    np.savetxt(buf, rows, delimiter=",", header=header, comments="", fmt="%.9g")

    png = velocities_png(
        vel, f"{d.name}: external ring generator velocities, omega_h = {omega_h:g} rad/s, a_w = {a_w:.3f} mm"
    )
    stem = Path(args.design).stem
    with atomic_batch() as batch:
        Path(batch.temp_path(out / f"{stem}_velocities.csv")).write_text(buf.getvalue())
        Path(batch.temp_path(out / f"{stem}_velocities.png")).write_bytes(png)
    i = int(np.argmax(np.abs(vel.V_sl)))
    print(f"  external ring generator, omega_h = {omega_h:g} rad/s, a_w = {a_w:.4f} mm:")
    print(
        f"    washer speed V_d = {vel.V_d[0]:.4g} mm/s; largest sliding speed |V_sl| = {abs(vel.V_sl[i]):.4g} mm/s at phi = {np.rad2deg(phi[i]):.1f} deg"
    )
    print(f"  wrote {stem}_velocities.csv and .png to {out}/")
    return EXIT_OK


def _refuse_velocity_flags(args, design) -> None:
    """A flag of the external ring generator's velocities given for another drive is refused, not ignored (a
    silently ignored flag reads as if it had taken effect). ``--out`` only gets a warning: a script may pass
    one folder to every command, and no figure depends on it."""
    why = (
        f"{design.drive.name} has [drive] deformation = '{design.drive.deformation}': kinematics gives its ratios only"
    )
    for flag, value in (("--omega-h", args.omega_h), ("--eccentricity", args.eccentricity)):
        if value is not None:
            raise DesignError(flag, f"sets the external ring generator's velocities, and {why}; drop the flag")
    if args.out is not None:
        print(f"wgcad: warning: --out: nothing written, {why}", file=sys.stderr)


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    k = sub.add_parser(
        "kinematics",
        help=COMMAND_HELP["kinematics"],
        epilog=epilog(five="the velocities picture needs wgcad[plots]"),
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
        type=bounded("kinematics", "--omega-h"),
        default=None,
        help="generator speed, rad/s (default 1: velocities per rad/s; [S3] uses 210); external deformation only",
    )
    k.add_argument(
        "--eccentricity",
        type=bounded("kinematics", "--eccentricity"),
        default=None,
        help="washer crank eccentricity a_w, mm (default W0); external deformation only",
    )
    k.set_defaults(func=cmd_kinematics)
