"""``wgcad generate``: DXF, STL, report.json and deformed-state pictures of a design."""

from __future__ import annotations

import json
import time
from pathlib import Path

from .common import EPILOG, EXIT_OK, add_memory_flag, angles_deg, circle, out_dir, angle_tag, positive_float

__all__ = ["register", "cmd_generate", "deformed_scene"]


def deformed_scene(drive, phi_h_abs: float) -> dict:
    """Geometry of the deformed drive at generator angle ``phi_h_abs`` (rad, relative to the fixed member)."""
    import numpy as np

    from ..kinematics import gear_ratios
    from ..placement import deformed_curve, join_teeth, place_flex_teeth, tooth_angles

    d = drive.design.drive
    ratios = gear_ratios(d.z_flex, d.z_rigid)
    if d.fixed == "rigid":
        phi_h, frame = phi_h_abs, 0.0
    else:  # flexspline fixed: the rigid gear turns by phi_h / u_hb; draw in the flexspline's frame
        phi_b = phi_h_abs / ratios["u_hb"]
        phi_h, frame = phi_h_abs - phi_b, phi_b
    teeth = place_flex_teeth(drive, phi_h, local=drive.flex.period)
    _, phi = tooth_angles(d.z_flex, d.z_rigid, phi_h)
    n_rim = max(720, int(np.ceil(2 * np.pi / np.sqrt(8 * drive.tol / drive.r_m))))
    ph = np.linspace(0.0, 2 * np.pi, n_rim, endpoint=False)
    rim = deformed_curve(drive.law, drive.r_m, drive.flex_rim_radius - drive.r_m, ph)
    neutral = deformed_curve(drive.law, drive.r_m, 0.0, ph)

    def rot(p, a):
        c, s = np.cos(a), np.sin(a)
        return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)

    teeth = rot(teeth, frame)
    outline = join_teeth(teeth)
    import shapely

    if not shapely.LinearRing(outline).is_simple:
        from ..errors import GeometryError

        raise GeometryError(f"deformed flexspline outline at generator angle {np.rad2deg(phi_h_abs):g} deg is not simple")
    # how far toward the minor axis the tips still overlap the rigid tip circle (close-up extent)
    R = np.hypot(teeth[..., 0], teeth[..., 1])
    over = (R.min(axis=1) < drive.rigid.r_a) if drive.external else (R.max(axis=1) > drive.rigid.r_a)
    phw = (phi + np.pi) % (2 * np.pi) - np.pi
    side = phw * (1.0 if d.rotation == "ccw" else -1.0)
    reach = side[over & (side >= 0) & (side <= np.pi / d.waves)]
    entry_deg = float(np.rad2deg(reach.max())) + 4.0 if reach.size else 45.0
    st = drive.law.state(ph)
    return {
        "flex_teeth": teeth,
        "flex_phi": phi,
        "flex_outline": outline,
        "entry_deg": min(entry_deg, 180.0 / d.waves),
        "neutral_phi": ph + phi_h + frame,
        "neutral_w": st.w,
        "r_m": drive.r_m,
        "waves": d.waves,
        "w0": drive.law.w0,
        "flex_rim": rot(rot(rim, phi_h), frame),
        "neutral": rot(rot(neutral, phi_h), frame),
        "rigid_outline": rot(drive.rigid.outline, frame),
        "rigid_rim_radius": drive.rigid_rim_radius,
        "major_axis": phi_h + frame,
        "entry_sign": 1.0 if d.rotation == "ccw" else -1.0,
        "r_ref": drive.rigid.r,
        "module": d.module,
        "rigid_outward": not drive.external,
        # radial window of the close-up: both gears' teeth, the flexspline's moved by up to +-1.2 W0
        "y_range": (
            min(drive.rigid.r_a, drive.rigid.r_f, drive.flex.r_a - 1.2 * drive.law.w0, drive.flex.r_f - 1.2 * drive.law.w0) - drive.rigid.r - 0.2 * d.module,
            max(drive.rigid.r_a, drive.rigid.r_f, drive.flex.r_a + 1.2 * drive.law.w0, drive.flex.r_f + 1.2 * drive.law.w0) - drive.rigid.r + 0.2 * d.module,
        ),
    }


def cmd_generate(args) -> int:
    t0 = time.perf_counter()
    from ..design import load_design
    from ..drive import build_drive
    from ..export.atomic import atomic_batch, ensure_writable_dir
    from ..report import drive_report, format_summary

    design = load_design(args.design)
    tol = args.chord_tol_um * 1e-3
    drive = build_drive(design, tol=tol, max_memory_mb=args.max_memory_mb, run={"exports": True})
    out = out_dir(args, args.design)
    ensure_writable_dir(out)
    import numpy as np

    from ..export.dxf import DxfLayer, write_dxf
    from ..export.figures import assembly_png
    from ..export.stl import ring_solid, write_stl

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
                rim_circle = circle(rim, tol)
                if rim < min(gear.r_a, gear.r_f):  # bore inside the teeth
                    mesh = ring_solid(gear.outline, [rim_circle], bw)
                else:  # teeth inside a ring
                    mesh = ring_solid(rim_circle, [gear.outline], bw)
                rep[name]["solid_volume_mm3"] = round(float(mesh.volume), 4)
                path = out / f"{stem}_{name}.stl"
                write_stl(batch.temp_path(path), mesh)
                files.append(path)
        for deg in args.generator_angle or []:
            scene = deformed_scene(drive, np.deg2rad(deg))
            tag = angle_tag(deg)
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
            png = assembly_png(scene, f"{design.drive.name}: generator at {deg:g} deg counter-clockwise from +x "
                                      f"({design.generator.law} law, W0 = {design.w0:.3f} mm"
                                      + (", generator's centre section)" if drive.coned else ")"),
                               entry_deg=scene["entry_deg"])
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



def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse

    g = sub.add_parser("generate", help="write DXF, STL, report.json (and deformed-state DXF/PNG) for a design",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    g.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    g.add_argument("--out", help="output folder (default: output/<design name>)")
    g.add_argument("--chord-tol-um", type=positive_float(0.0, 100.0, "um"), default=1.0,
                   help="largest distance between outline and exact curve, um (default 1)")
    g.add_argument("--generator-angle", type=angles_deg, metavar="DEG[,DEG...]",
                   help="also write the deformed assembly (DXF + PNG) at these generator angles, degrees")
    g.add_argument("--no-stl", action="store_true", help="skip the STL solids")
    g.add_argument("--json", action="store_true", help="print report.json to stdout instead of the summary")
    g.add_argument("--quiet", action="store_true", help="print nothing on success")
    add_memory_flag(g)
    g.set_defaults(func=cmd_generate)
