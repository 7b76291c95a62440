"""Command-line interface: ``wgcad generate`` and ``wgcad kinematics`` (heavy modules imported lazily)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from . import __version__
from .errors import WgcadError

__all__ = ["main", "EXIT_OK", "EXIT_INTERFERENCE", "EXIT_INPUT"]

EXIT_OK = 0
EXIT_INTERFERENCE = 1  # reserved for `wgcad audit`: interference found
EXIT_INPUT = 2  # bad design file, flag or output folder; nothing written

EPILOG = """exit codes:
  0  success
  1  interference found (audit)
  2  bad input: design file, flag, or output folder (one-line message, nothing written)
"""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2, no usage dump."""

    def error(self, message):  # noqa: D401
        self.exit(EXIT_INPUT, f"wgcad: error: {message}\n")


class _UsageError(WgcadError, ValueError):
    pass


def _angles_deg(text: str) -> list[float]:
    out = []
    for part in text.split(","):
        part = part.strip()
        try:
            val = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{part}' is not a number (degrees, comma separated)") from None
        if not -3600.0 <= val <= 3600.0:
            raise argparse.ArgumentTypeError(f"{val:g} deg is outside [-3600, 3600]")
        out.append(val)
    return out


def _positive_float(lo: float, hi: float, unit: str):
    def conv(text: str) -> float:
        try:
            val = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not lo < val <= hi:
            raise argparse.ArgumentTypeError(f"must be in ({lo:g}, {hi:g}] {unit}, got {val:g}")
        return val

    return conv


def _out_dir(args, design_path: str) -> Path:
    return Path(args.out) if args.out else Path("output") / Path(design_path).stem


def _angle_tag(deg: float) -> str:
    return f"{deg:+08.3f}".replace("+", "p").replace("-", "m").replace(".", "_")


def _circle(radius: float, tol: float):
    import numpy as np

    step = 2.0 * np.arccos(max(-1.0, 1.0 - tol / radius))
    n = max(64, int(np.ceil(2 * np.pi / step)))
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)


def deformed_scene(drive, phi_h_abs: float) -> dict:
    """Geometry of the deformed drive at generator angle ``phi_h_abs`` (rad, relative to the fixed member)."""
    import numpy as np

    from .kinematics import gear_ratios
    from .placement import deformed_curve, place_flex_teeth, tooth_angles

    d = drive.design.drive
    ratios = gear_ratios(d.z_flex, d.z_rigid)
    if d.fixed == "rigid":
        phi_h, frame = phi_h_abs, 0.0
    else:  # flexspline fixed: the rigid gear turns by phi_h / u_hb; draw in the flexspline's frame
        phi_b = phi_h_abs / ratios["u_hb"]
        phi_h, frame = phi_h_abs - phi_b, phi_b
    local = drive.flex.period[:-1]
    teeth = place_flex_teeth(drive, phi_h, local=local)
    _, phi = tooth_angles(d.z_flex, d.z_rigid, phi_h)
    n_rim = max(720, int(np.ceil(2 * np.pi / np.sqrt(8 * drive.tol / drive.r_m))))
    ph = np.linspace(0.0, 2 * np.pi, n_rim, endpoint=False)
    rim = deformed_curve(drive.law, drive.r_m, drive.flex_rim_radius - drive.r_m, ph)
    neutral = deformed_curve(drive.law, drive.r_m, 0.0, ph)

    def rot(p, a):
        c, s = np.cos(a), np.sin(a)
        return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)

    teeth = rot(teeth, frame)
    return {
        "flex_teeth": teeth,
        "flex_phi": phi,
        "flex_outline": teeth.reshape(-1, 2),
        "flex_rim": rot(rot(rim, phi_h), frame),
        "neutral": rot(rot(neutral, phi_h), frame),
        "rigid_outline": rot(drive.rigid.outline, frame),
        "rigid_rim_radius": drive.rigid_rim_radius,
        "major_axis": phi_h + frame,
        "entry_sign": 1.0 if d.rotation == "ccw" else -1.0,
        "r_ref": drive.rigid.r,
        "module": d.module,
        "rigid_outward": not drive.external,
        "y_range": tuple(np.array(sorted((drive.flex.r_f, drive.rigid.r_f))) - drive.rigid.r + [-0.3 * d.module, 0.3 * d.module]),
    }


def cmd_generate(args) -> int:
    t0 = time.perf_counter()
    from .design import load_design
    from .drive import build_drive
    from .export.atomic import atomic_batch, ensure_writable_dir
    from .report import drive_report, format_summary

    design = load_design(args.design)
    tol = args.chord_tol_um * 1e-3
    drive = build_drive(design, tol=tol)
    out = _out_dir(args, args.design)
    ensure_writable_dir(out)
    import numpy as np

    from .export.dxf import DxfLayer, write_dxf
    from .export.figures import assembly_png
    from .export.stl import ring_solid, write_stl

    stem = Path(args.design).stem
    f, b = drive.flex, drive.rigid
    layers = [
        DxfLayer("FLEXSPLINE", outlines=(f.outline,), color=5),
        DxfLayer("FLEXSPLINE_RIM", circles=((0.0, 0.0, drive.flex_rim_radius),), color=5),
        DxfLayer("RIGID", outlines=(b.outline,), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
    ]
    rep = drive_report(drive)
    files = []
    with atomic_batch() as batch:
        path = out / f"{stem}.dxf"
        write_dxf(batch.temp_path(path), layers)
        files.append(path)
        if not args.no_stl:
            bw = design.drive.face_width
            for name, gear, rim in (("flexspline", f, drive.flex_rim_radius), ("rigid", b, drive.rigid_rim_radius)):
                circle = _circle(rim, tol)
                if rim < min(gear.r_a, gear.r_f):  # bore inside the teeth
                    mesh = ring_solid(gear.outline, [circle], bw)
                else:  # teeth inside a ring
                    mesh = ring_solid(circle, [gear.outline], bw)
                rep[name]["solid_volume_mm3"] = round(float(mesh.volume), 4)
                path = out / f"{stem}_{name}.stl"
                write_stl(batch.temp_path(path), mesh)
                files.append(path)
        for deg in args.generator_angle or []:
            scene = deformed_scene(drive, np.deg2rad(deg))
            tag = _angle_tag(deg)
            dl = [
                DxfLayer("RIGID", outlines=(scene["rigid_outline"],), color=1),
                DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
                DxfLayer("FLEXSPLINE_DEFORMED", outlines=(scene["flex_outline"],), color=5),
                DxfLayer("FLEXSPLINE_RIM_DEFORMED", outlines=(scene["flex_rim"],), color=5),
                DxfLayer("NEUTRAL_LINE", outlines=(scene["neutral"],), color=3),
            ]
            path = out / f"{stem}_phi{tag}.dxf"
            write_dxf(batch.temp_path(path), dl)
            files.append(path)
            png = assembly_png(scene, f"{design.drive.name}: generator at {deg:g} deg ({design.generator.law} law, W0 = {design.w0:.3f} mm)")
            path = out / f"{stem}_phi{tag}.png"
            Path(batch.temp_path(path)).write_bytes(png)
            files.append(path)
        rep["generator_angles_deg"] = list(args.generator_angle or [])
        rep["files"] = [p.name for p in files] + ["report.json"]
        # no timings in report.json: the same design must give byte-identical files
        path = out / "report.json"
        Path(batch.temp_path(path)).write_text(json.dumps(rep, indent=2, sort_keys=False) + "\n")
    if args.json:
        print(json.dumps(rep, indent=2))
    elif not args.quiet:
        print(format_summary(rep))
        print(f"\n  wrote {len(files) + 1} files to {out}/ in {time.perf_counter() - t0:.2f} s")
    return EXIT_OK


def cmd_kinematics(args) -> int:
    import numpy as np

    from .design import load_design
    from .drive import build_drive
    from .kinematics import gear_ratios

    design = load_design(args.design)
    drive = build_drive(design)
    d = design.drive
    r = gear_ratios(d.z_flex, d.z_rigid)

    def sense(u):
        return "same direction as the generator" if u > 0 else "opposite to the generator"

    print(f"{d.name}")
    print(f"  rigid gear fixed:      u_hg = {r['u_hg']:g}  (flexspline turns {sense(r['u_hg'])})")
    print(f"  flexspline fixed:      u_hb = {r['u_hb']:g}  (rigid gear turns {sense(r['u_hb'])})")
    print(f"  mesh period (perfect gears): {360.0 / d.z_rigid:.6g} deg of generator rotation")
    if not design.external:
        return EXIT_OK
    from .export.atomic import atomic_batch, ensure_writable_dir
    from .kinematics import ring_generator_velocities

    out = _out_dir(args, args.design)
    ensure_writable_dir(out)
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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 2, figsize=(13, 4.5), dpi=90)
    for c in ("V_w", "V_v", "V_wK", "V_vK", "V_sl", "V_dw", "V_dv"):
        axs[0].plot(np.rad2deg(phi), getattr(vel, c), label=c)
    axs[0].set_xlabel("phi, deg from the washer contact (major axis)")
    axs[0].set_ylabel("mm/s")
    axs[0].legend(fontsize=7, ncol=2)
    axs[0].grid(alpha=0.3)
    axs[1].plot(np.rad2deg(phi), vel.dtheta_dt, color="k")
    axs[1].set_xlabel("phi, deg")
    axs[1].set_ylabel("dtheta/dt, rad/s")
    axs[1].grid(alpha=0.3)
    fig.suptitle(f"{d.name}: external ring generator velocities, omega_h = {args.omega_h:g} rad/s, a_w = {a_w:.3f} mm")
    fig.tight_layout()
    png = io.BytesIO()
    fig.savefig(png, format="png")
    plt.close(fig)
    stem = Path(args.design).stem
    with atomic_batch() as batch:
        Path(batch.temp_path(out / f"{stem}_velocities.csv")).write_text(buf.getvalue())
        Path(batch.temp_path(out / f"{stem}_velocities.png")).write_bytes(png.getvalue())
    i = int(np.argmax(np.abs(vel.V_sl)))
    print(f"  external ring generator, omega_h = {args.omega_h:g} rad/s, a_w = {a_w:.4f} mm:")
    print(f"    washer speed V_d = {vel.V_d[0]:.4g} mm/s; largest sliding speed |V_sl| = {abs(vel.V_sl[i]):.4g} mm/s at phi = {np.rad2deg(phi[i]):.1f} deg")
    print(f"  wrote {stem}_velocities.csv and .png to {out}/")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="wgcad", description="Geometry, deformation and clearance of harmonic (strain-wave) drives.",
                epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"wgcad {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    g = sub.add_parser("generate", help="write DXF, STL, report.json (and deformed-state DXF/PNG) for a design",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    g.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    g.add_argument("--out", help="output folder (default: output/<design name>)")
    g.add_argument("--chord-tol-um", type=_positive_float(0.0, 100.0, "um"), default=1.0,
                   help="largest distance between outline and exact curve, um (default 1)")
    g.add_argument("--generator-angle", type=_angles_deg, metavar="DEG[,DEG...]",
                   help="also write the deformed assembly (DXF + PNG) at these generator angles, degrees")
    g.add_argument("--no-stl", action="store_true", help="skip the STL solids")
    g.add_argument("--json", action="store_true", help="print report.json to stdout instead of the summary")
    g.add_argument("--quiet", action="store_true", help="print nothing on success")
    g.set_defaults(func=cmd_generate)

    k = sub.add_parser("kinematics", help="gear ratios; velocities of the external ring generator (CSV + PNG)",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    k.add_argument("design")
    k.add_argument("--out", help="output folder (default: output/<design name>)")
    k.add_argument("--omega-h", type=_positive_float(0.0, 1e6, "rad/s"), default=1.0,
                   help="generator speed, rad/s (default 1: velocities per rad/s; [S3] uses 210)")
    k.add_argument("--eccentricity", type=_positive_float(0.0, 100.0, "mm"), default=None,
                   help="washer crank eccentricity a_w, mm (default W0)")
    k.set_defaults(func=cmd_kinematics)
    return p


def main(argv=None) -> int:
    """Entry point of the ``wgcad`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except WgcadError as e:
        print(f"wgcad: error: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("wgcad: interrupted; nothing was written", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
