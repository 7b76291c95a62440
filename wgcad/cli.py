"""Command-line interface: ``wgcad generate``, ``audit`` and ``kinematics`` (heavy modules imported lazily)."""

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
        if val == 0.0:
            val = 0.0  # -0 is 0
        if val not in out:
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


def _angle_count(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 4 <= n <= 3_600_000:
        raise argparse.ArgumentTypeError(f"must be 4..3600000 angles per revolution, got {n}")
    return n


def _out_dir(args, design_path: str) -> Path:
    return Path(args.out) if args.out else Path("output") / Path(design_path).stem


def _angle_tag(deg: float) -> str:
    # angles closer than the tag's 1e-3 deg resolution share a file name: keep 6 decimals then
    tag = f"{deg:+08.3f}"
    if abs(round(deg, 3) - deg) > 1e-9:
        tag = f"{deg:+011.6f}"
    return tag.replace("+", "p").replace("-", "m").replace(".", "_")


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
    from .placement import deformed_curve, join_teeth, place_flex_teeth, tooth_angles

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
        from .errors import GeometryError

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
    z_ref = d.z_rigid if d.fixed == "rigid" else d.z_flex
    print(f"  mesh period (perfect gears): {360.0 / z_ref:.6g} deg of generator rotation "
          f"(the {'rigid' if d.fixed == 'rigid' else 'flexspline'} teeth pass one pitch)")
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


class _Progress:
    """A one-line progress bar on stderr, only when stderr is a terminal (or forced)."""

    def __init__(self, enabled: bool):
        self.enabled = enabled

    def __call__(self, done, total, stage):
        if self.enabled:
            n = int(30 * done / total)
            sys.stderr.write(f"\r[{'#' * n}{'.' * (30 - n)}] {stage:<12s}")
            sys.stderr.flush()
            if done == total:
                sys.stderr.write("\n")


def _audit_summary(name: str, res: dict) -> str:
    w = res["worst"]
    where = f"tooth {w['tooth']} at generator angle {w['generator_angle_deg']:.3f} deg (tooth {w['tooth_angle_deg']:+.3f} deg from the major axis)"
    if w["section_z_mm"] is not None:
        where += f", section z = {w['section_z_mm']:g} mm"
    lines = [f"{name}: clearance audit ({res['settings']['engine']} engine)"]
    lines.append(f"  minimum clearance: {res['min_clearance_um']:.3f} um, {w['location']}, {where}")
    if res["interference"]:
        lines.append(f"  INTERFERENCE: penetration {-res['min_clearance_um']:.3f} um deeper than the tolerance "
                     f"{res['interference_tol_um']:g} um (overlap area {w['overlap_area_um2']:.1f} um^2)")
    elif res["min_clearance_um"] < res["interference_tol_um"]:
        lines.append(f"  contact within the tolerance ({res['interference_tol_um']:g} um): no interference")
    else:
        lines.append("  no interference")
    e = res["entry"]
    if res["entry_gap_um"] is not None:
        sec = "" if e["section_z_mm"] is None else f", section z = {e['section_z_mm']:g} mm"
        lines.append(f"  entry gap: {res['entry_gap_um']:.3f} um at tooth angle {e['tooth_angle_deg']:+.3f} deg{sec} "
                     "(flexspline tip crossing the rigid tip circle)")
        if e["pinch_um"] is None:
            lines.append("  entry pinch: none (no local minimum within 6 deg of the crossing)")
        else:
            psec = "" if e["pinch_section_z_mm"] is None else f", section z = {e['pinch_section_z_mm']:g} mm"
            lines.append(f"  entry pinch: {e['pinch_um']:.3f} um at tooth angle {e['pinch_tooth_angle_deg']:+.3f} deg{psec}, {e['pinch_location']}"
                         + ("  TIP-TO-TIP RISK" if e["tip_to_tip_risk"] else ""))
    else:
        lines.append("  entry gap: none (the tips never cross the rigid tip circle)")
    b = res["backlash_at"]
    if res["backlash_arcmin"] is None:
        lines.append(f"  backlash: none, teeth interfere at generator angle {b['generator_angle_deg']:g} deg")
    else:
        lines.append(f"  backlash: {res['backlash_arcmin']:.4f} arcmin = {res['backlash_um_at_pitch']:.2f} um at the rigid pitch circle "
                     f"(generator angle {b['generator_angle_deg']:g} deg)")
    c = res["counts"]
    lines.append(f"  computed {c['evaluated']} of {c['samples']} tooth samples exactly "
                 f"({c['unique_tooth_angles']} distinct tooth angles, {c['culled']} culled by radius) in {res['elapsed_s']:.3f} s")
    return "\n".join(lines)


def cmd_audit(args) -> int:
    from .audit import RunSettings, run_audit
    from .export.atomic import atomic_batch, ensure_writable_dir
    from .regression import baseline_figures, compare, format_drifts, load_baseline, make_baseline

    base = load_baseline(args.baseline) if args.baseline else None
    if base is not None:
        st = base["settings"]
        rs = RunSettings(step_deg=float(st["step_deg"]), sections=int(st["sections"]),
                         chord_tol_um=float(st["chord_tol_um"]), interference_tol_um=float(st["interference_tol_um"]))
    else:
        step = 360.0 / args.angles if args.angles else args.step_deg
        off = args.no_shortcuts
        rs = RunSettings(step_deg=step, sections=args.sections, chord_tol_um=args.chord_tol_um,
                         interference_tol_um=args.interference_tol_um,
                         use_period=not (off or args.no_mesh_period), use_waves=not (off or args.no_wave_symmetry),
                         use_mirror=not (off or args.no_mirror), cull=not (off or args.no_culling),
                         bound=not (off or args.no_bound))
    rs.check()
    for path in (args.json, args.plot, args.write_baseline):
        if path:
            ensure_writable_dir(Path(path).parent if str(Path(path).parent) else Path("."))
    drive, result = run_audit(args.design, rs, progress=_Progress(args.progress or sys.stderr.isatty()))
    res = result.to_json()
    res["design"] = drive.design.drive.name
    res["source"] = drive.design.source
    if args.engine in ("fcl", "both"):
        from .clearance.fcl3d import verify_worst

        res["fcl"] = verify_worst(drive, result)
        if args.engine == "fcl":
            res["settings"]["engine"] = "fcl (3D check of the pairs the 2D engine singles out)"
        else:
            res["settings"]["engine"] = "2d + fcl"
    drifts = None
    if base is not None:
        drifts = compare(base, baseline_figures(drive, res))
        res["baseline"] = {"path": str(args.baseline), "drifts": [d.__dict__ for d in drifts]}
    with atomic_batch() as batch:
        if args.json:
            Path(batch.temp_path(args.json)).write_text(json.dumps(res, indent=2) + "\n")
        if args.write_baseline:
            doc = make_baseline(str(args.design), {k: v for k, v in rs.as_dict().items()
                                                    if k in ("step_deg", "sections", "chord_tol_um", "interference_tol_um")},
                                drive, res)
            Path(batch.temp_path(args.write_baseline)).write_text(json.dumps(doc, indent=2) + "\n")
        if args.plot:
            for suffix, png in _audit_pngs(drive, result):
                p = Path(args.plot)
                Path(batch.temp_path(p.with_name(f"{p.stem}_{suffix}.png"))).write_bytes(png)
    if not args.quiet:
        print(_audit_summary(res["design"], res))
        if "fcl" in res:
            f = res["fcl"]
            print(f"  FCL 3D check of the pairs the 2D engine singled out: {f['summary']}")
        if drifts is not None:
            print(f"  baseline {args.baseline}: {format_drifts(drifts)}")
    if drifts:
        return EXIT_INTERFERENCE
    return EXIT_INTERFERENCE if res["interference"] else EXIT_OK


def _audit_pngs(drive, result):
    import numpy as np
    import shapely

    from .clearance.engine import Scene, clearance_profile, clearance_vs_angle
    from .export.figures import clearance_profile_png, clearance_vs_angle_png, tightest_spot_png
    from .placement import tooth_pose, transform

    scene = Scene(drive)
    secs = [None] if not drive.coned else [s for s in result.settings["sections_z_mm"]]
    prof = clearance_profile(scene, secs)
    w = result.worst
    e = result.entry
    name = drive.design.drive.name
    data = {
        "phi_deg": np.rad2deg(prof["phi"]),
        "sections": [{"z": s["z"], "working_um": 1e3 * s["working"], "nonworking_um": 1e3 * s["nonworking"]} for s in prof["sections"]],
        "entry_deg": e["tooth_angle_deg"],
        "entry_um": 1e3 * result.entry_gap,
        "worst_deg": w["tooth_angle_deg"],
        "worst_um": w["clearance_um"],
        "tol_um": 1e3 * result.interference_tol,
    }
    yield "profile", clearance_profile_png(data, f"{name}: clearance of a flexspline tooth along its passage (every tooth follows it)")
    mesh = 360.0 / drive.design.drive.z_rigid
    ang = np.deg2rad(np.linspace(0.0, 3 * mesh, 601))
    wv, nv = clearance_vs_angle(scene, prof, ang)
    yield "vs_angle", clearance_vs_angle_png(np.rad2deg(ang), 1e3 * wv, 1e3 * nv, 1e3 * result.interference_tol,
                                             f"{name}: smallest clearance over all teeth; periodic with the mesh period {mesh:.4f} deg (3 shown)")
    # the teeth around the tightest spot, at the worst sample's generator angle and section
    phi_h = np.deg2rad(w["generator_angle_deg"])
    z = w["section_z_mm"]
    d = drive.design.drive
    k = (w["tooth"] + np.arange(-3, 4)) % d.z_flex
    mat = 2 * np.pi * k / d.z_flex + phi_h / scene.ratios["u_hg"]
    rot, shift = tooth_pose(scene.law(z), mat - phi_h, drive.r_m, frame_angle=phi_h)
    teeth = transform(scene.flex_local, rot, shift)
    lo, up, _ = scene.neighbours(shift, rot)
    rig_idx = np.unique(np.concatenate([lo, up]))
    rig = scene.rigid_pts[rig_idx]
    overlaps = []
    for t in teeth[3:4]:  # the worst tooth
        a = shapely.Polygon(t)
        for j in rig_idx:
            inter = a.intersection(scene.rigid_geoms[j])
            for g in getattr(inter, "geoms", [inter]):
                if g.geom_type == "Polygon" and not g.is_empty:
                    overlaps.append(np.asarray(g.exterior.coords))
    labels = [f"{np.rad2deg(((p + np.pi) % (2 * np.pi)) - np.pi):.1f} deg" for p in (mat - phi_h)]
    sec = "" if z is None else f", section z = {z:g} mm"
    yield "tightest", tightest_spot_png(teeth, labels, rig, overlaps,
                                        f"{name}: tightest spot, tooth {w['tooth']} at generator angle {w['generator_angle_deg']:g} deg{sec}: "
                                        f"{w['clearance_um']:.2f} um ({w['location']})")


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

    a = sub.add_parser("audit", help="clearance and interference over the generator cycle; exit 1 on interference or baseline drift",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("design")
    grp = a.add_mutually_exclusive_group()
    grp.add_argument("--angles", type=_angle_count, metavar="N", help="N generator angles over a full revolution")
    grp.add_argument("--step-deg", type=_positive_float(0.0, 90.0, "deg"), default=0.5, help="generator-angle step, deg (default 0.5)")
    a.add_argument("--sections", type=int, default=3, help="cross-sections over the face width when the flexspline is coned (default 3)")
    a.add_argument("--engine", choices=("2d", "fcl", "both"), default="2d",
                   help="2d (default); fcl/both: also check the tightest pairs with 3D solids in python-fcl")
    a.add_argument("--chord-tol-um", type=_positive_float(0.0, 100.0, "um"), default=1.0,
                   help="largest distance between outline and exact curve, um (default 1)")
    a.add_argument("--interference-tol-um", type=float, default=1.0, help="penetration reported as contact, um (default 1)")
    a.add_argument("--json", metavar="PATH", help="write the results as JSON")
    a.add_argument("--plot", metavar="PATH", help="write PNGs PATH_profile.png, PATH_vs_angle.png, PATH_tightest.png (PATH without .png)")
    a.add_argument("--write-baseline", metavar="BASE.json", help="record the key figures with their tolerances")
    a.add_argument("--baseline", metavar="BASE.json", help="recompute with the baseline's settings; exit 1 on drift")
    a.add_argument("--no-shortcuts", action="store_true", help="compute everything (no mesh period, symmetries, culling or bounding)")
    a.add_argument("--no-mesh-period", action="store_true")
    a.add_argument("--no-wave-symmetry", action="store_true")
    a.add_argument("--no-mirror", action="store_true")
    a.add_argument("--no-culling", action="store_true")
    a.add_argument("--no-bound", action="store_true")
    a.add_argument("--progress", action="store_true", help="progress bar on stderr even when it is not a terminal")
    a.add_argument("--quiet", action="store_true")
    a.set_defaults(func=cmd_audit)

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
