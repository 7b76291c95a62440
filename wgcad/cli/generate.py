"""``wgcad generate``: DXF, STL, <design>.report.json and deformed-state pictures of a design."""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from .common import EPILOG, EXIT_OK, add_memory_flag, angle_tag, angles_deg, circle, out_dir, positive_float

__all__ = ["register", "cmd_generate", "deformed_scene", "report_name"]


def deformed_scene(drive, phi_h_abs: float, imp=None) -> dict:
    """Geometry of the deformed drive at generator angle ``phi_h_abs`` (rad, relative to the fixed member).

    With ``imp`` (:class:`wgcad.placement.imperfect.Imperfections`, rigid gear
    fixed) every tooth of both gears sits where its errors put it
    (``flex_poses``, ``rigid_poses``), and the rim and neutral line move with
    the cam offset (docs/models.md 6.2).
    """
    import numpy as np

    from ..kinematics import gear_ratios
    from ..placement import deformed_curve, join_teeth, place_flex_teeth, tooth_angles, transform

    d = drive.design.drive
    ratios = gear_ratios(d.z_flex, d.z_rigid)
    if d.fixed == "rigid":
        phi_h, frame = phi_h_abs, 0.0
    else:  # flexspline fixed: the rigid gear turns by phi_h / u_hb; draw in the flexspline's frame
        phi_b = phi_h_abs / ratios["u_hb"]
        phi_h, frame = phi_h_abs - phi_b, phi_b
    _, phi = tooth_angles(d.z_flex, d.z_rigid, phi_h)
    if imp is not None:
        from ..placement.imperfect import cam_offset, flex_poses, rigid_poses

        teeth = transform(drive.flex.period, *flex_poses(drive, imp, phi_h))
        rigid_outline = join_teeth(transform(drive.rigid.period, *rigid_poses(drive, imp)))
        E = cam_offset(imp, phi_h, phi_h / ratios["u_hg"])  # the rim and its neutral line move with the cam
    else:
        teeth = place_flex_teeth(drive, phi_h, local=drive.flex.period)
        rigid_outline, E = drive.rigid.outline, np.zeros(2)
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

        raise GeometryError(
            f"deformed flexspline outline at generator angle {np.rad2deg(phi_h_abs):g} deg is not simple"
        )
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
        "flex_rim": rot(rot(rim, phi_h), frame) + E,
        "neutral": rot(rot(neutral, phi_h), frame) + E,
        "rigid_outline": rot(rigid_outline, frame),
        "imperfect": imp is not None,
        "rigid_rim_radius": drive.rigid_rim_radius,
        "major_axis": phi_h + frame,
        "entry_sign": 1.0 if d.rotation == "ccw" else -1.0,
        "r_ref": drive.rigid.r,
        "module": d.module,
        "rigid_outward": not drive.external,
        # radial window of the close-up: both gears' teeth, the flexspline's moved by up to +-1.2 W0
        "y_range": (
            min(
                drive.rigid.r_a,
                drive.rigid.r_f,
                drive.flex.r_a - 1.2 * drive.law.w0,
                drive.flex.r_f - 1.2 * drive.law.w0,
            )
            - drive.rigid.r
            - 0.2 * d.module,
            max(
                drive.rigid.r_a,
                drive.rigid.r_f,
                drive.flex.r_a + 1.2 * drive.law.w0,
                drive.flex.r_f + 1.2 * drive.law.w0,
            )
            - drive.rigid.r
            + 0.2 * d.module,
        ),
    }


# Relative cost of the steps of `generate`, for the progress bar (measured on D1 involute:
# build 0.01-0.04 s, DXF 0.03 s, one STL 0.2-0.8 s, one deformed-state picture 3.5-5.5 s
# on a loaded 2-core machine); only the bar's pace depends on them.
_COST = {"design": 0.3, "dxf": 0.3, "stl": 2.0, "angle_dxf": 1.0, "angle_png": 15.0, "report": 0.2}


def report_name(stem: str) -> str:
    """``<design>.report.json``: one report per design, so designs can share an output folder."""
    return f"{stem}.report.json"


def cmd_generate(args) -> int:
    from .common import Progress, want_progress
    from .outputs import Manifest, check_output_dir, manifest_name, write_stdout

    t0 = time.perf_counter()
    bar = Progress(want_progress(args.progress) and (args.progress or not args.quiet))
    angles = list(args.generator_angle or [])
    total = (
        _COST["design"]
        + _COST["dxf"]
        + (0 if args.no_stl else 2 * _COST["stl"])
        + len(angles) * (_COST["angle_dxf"] + _COST["angle_png"])
        + _COST["report"]
    )
    done = 0.0

    def step(cost, next_stage):
        """A step of relative cost ``cost`` is finished; ``next_stage`` starts."""
        nonlocal done
        done += cost
        bar.set(done / total, next_stage)

    bar.start("loading modules")
    from ..atomic import check_target
    from ..design import load_design
    from ..drive import build_drive
    from ..report import drive_report, format_summary

    bar.set(0.0, "reading the design")

    design = load_design(args.design)
    tol = args.chord_tol_um * 1e-3
    drive = build_drive(design, tol=tol, max_memory_mb=args.max_memory_mb, run={"exports": True})
    out = out_dir(args, args.design)
    check_output_dir(out)
    stem = Path(args.design).stem
    manifest = Manifest(out, stem, Path(args.design))
    manifest.check_collision(args.force)
    # every file this run will write is judged before any work: a device, FIFO, folder or link
    # in the way stops the run now, not after minutes of computing
    planned = [f"{stem}.dxf", report_name(stem), manifest_name(stem)]
    planned += [] if args.no_stl else [f"{stem}_flexspline.stl", f"{stem}_rigid.stl"]
    planned += [f"{stem}_phi{angle_tag(deg)}.{ext}" for deg in angles for ext in ("dxf", "png")]
    for name in planned:
        check_target(out / name)
        if (out / name).exists() and os.path.samefile(out / name, args.design):
            from ..errors import OutputError

            raise OutputError(f"{out / name}: is the design file itself; it would be overwritten (give another --out)")

    from ..atomic import atomic_batch
    from ..export.dxf import DxfLayer, write_dxf

    step(_COST["design"], "DXF")
    f, b = drive.flex, drive.rigid
    from ..profiles.band import gear_band_outline

    # the exported outlines run in a symmetric band around the exact curves (docs/models.md, appendix A):
    # chords through curve points would make every convex flank thin, every space narrow
    band = {"flexspline": gear_band_outline(f), "rigid": gear_band_outline(b)}
    layers = [
        DxfLayer("FLEXSPLINE", outlines=(band["flexspline"],), color=5),
        DxfLayer("FLEXSPLINE_RIM", circles=((0.0, 0.0, drive.flex_rim_radius),), color=5),
        DxfLayer("RIGID", outlines=(band["rigid"],), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
    ]
    rep = drive_report(drive)
    from .common import not_modelled

    # the deformed assembly places the parts with their errors (rigid gear fixed: docs/models.md 6.2); the
    # gears' own DXF and STL stay nominal, the part a shop makes
    imp = None
    if design.imperfections.any and design.drive.fixed == "rigid":
        from ..placement.imperfect import Imperfections

        imp = Imperfections.from_spec(design.imperfections)
    rep["not_modelled"] = not_modelled(design, "generate", imperfections=imp is not None)
    if imp is not None:
        rep["imperfections"] = (
            "the deformed-assembly DXF/PNG (--generator-angle) place every tooth with its [imperfections]; "
            "the gears' DXF and STL are the nominal parts"
        )
    files = []
    with atomic_batch() as batch:
        path = out / f"{stem}.dxf"
        write_dxf(batch.temp_path(path), layers)
        files.append(path)
        step(_COST["dxf"], "STL")
        if not args.no_stl:
            from ..export.stl import ring_solid, write_stl

            bw = design.drive.face_width
            for name, gear, rim in (("flexspline", f, drive.flex_rim_radius), ("rigid", b, drive.rigid_rim_radius)):
                bar.set(done / total, f"STL {name}")
                rim_circle = circle(rim, tol)
                if rim < min(gear.r_a, gear.r_f):  # bore inside the teeth
                    mesh = ring_solid(band[name], [rim_circle], bw)
                else:  # teeth inside a ring
                    mesh = ring_solid(rim_circle, [band[name]], bw)
                rep[name]["solid_volume_mm3"] = round(float(mesh.volume), 4)
                path = out / f"{stem}_{name}.stl"
                write_stl(batch.temp_path(path), mesh)
                files.append(path)
                step(_COST["stl"], f"STL {name}")
        if angles:
            import numpy as np

            from ..export.figures import assembly_png
        for deg in angles:
            bar.set(done / total, f"{deg:g} deg: DXF")
            scene = deformed_scene(drive, np.deg2rad(deg), imp)
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
            step(_COST["angle_dxf"], f"{deg:g} deg: picture")
            png = assembly_png(
                scene,
                f"{design.drive.name}: generator at {deg:g} deg counter-clockwise from +x "
                f"({design.generator.law} law, W0 = {design.w0:.3f} mm"
                + (", generator's centre section" if drive.coned else "")
                + (", parts with their [imperfections])" if imp is not None else ")"),
                entry_deg=scene["entry_deg"],
            )
            path = out / f"{stem}_phi{tag}.png"
            Path(batch.temp_path(path)).write_bytes(png)
            files.append(path)
            step(_COST["angle_png"], f"{deg:g} deg: picture")
        bar.set(done / total, "report")
        rep["generator_angles_deg"] = angles
        report_path = out / report_name(stem)
        rep["files"] = [p.name for p in files] + [report_path.name]
        # no timings in the report: the same design must give byte-identical files
        Path(batch.temp_path(report_path)).write_text(
            json.dumps(rep, allow_nan=False, indent=2, sort_keys=False) + "\n"
        )
        files.append(report_path)
        # the previous run's files for this design that this run does not write again go with the commit
        stale, kept = manifest.stale_files(p.name for p in files)
        for p in stale:
            batch.remove_on_commit(p)
        Path(batch.temp_path(out / manifest_name(stem))).write_text(manifest.document(batch.pairs))
    bar.set(1.0, "done")
    bar.close()
    for name in kept:
        print(f"wgcad: warning: kept {out / name}: an earlier run wrote it, but it was changed since", file=sys.stderr)
    if args.json:
        write_stdout(json.dumps(rep, allow_nan=False, indent=2) + "\n")
    elif not args.quiet:
        removed = f", removed {len(stale)} of the previous run's files" if stale else ""
        write_stdout(
            format_summary(rep)
            + "\n"
            + "".join(f"  NOT MODELLED: {n}\n" for n in rep["not_modelled"])
            + (f"  [imperfections]: {rep['imperfections']}\n" if "imperfections" in rep else "")
            + f"\n  wrote {len(files)} files to {out}/ ({report_path.name}){removed} in {time.perf_counter() - t0:.2f} s\n"
        )
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    import argparse
    import textwrap

    g = sub.add_parser(
        "generate",
        help="write DXF, STL, <design>.report.json (and deformed-state DXF/PNG) for a design",
        description=textwrap.fill(
            "Write the manufacturing files of a design into one folder: <design>.dxf, "
            "<design>_flexspline.stl, <design>_rigid.stl, <design>.report.json and, per --generator-angle, "
            "<design>_phi<angle>.dxf/.png. Several designs can share a folder (each file starts with the design "
            "file's name). A re-run replaces this design's files and removes those of its previous run that it "
            "does not write again (listed in the hidden .<design>.wgcad-files.json), nothing else, "
            "and the temporary files a killed run left (.<file>.<pid>-<hex>.tmp).",
            width=79,
        ),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g.add_argument("design", help="design file (TOML), e.g. templates/d1_involute.toml")
    g.add_argument(
        "--out", metavar="DIR", help="output folder (default: output/<design name>); created when the files are written"
    )
    g.add_argument(
        "--chord-tol-um",
        type=positive_float(0.0, 100.0, "um"),
        default=1.0,
        help="largest distance between outline and exact curve, um (default 1)",
    )
    g.add_argument(
        "--generator-angle",
        type=angles_deg,
        metavar="DEG[,DEG...]",
        help="also write the deformed assembly (DXF + PNG) at these generator angles, degrees",
    )
    g.add_argument("--no-stl", action="store_true", help="skip the STL solids (and the import of the 3D libraries)")
    g.add_argument(
        "--force",
        action="store_true",
        help="replace the files that a different design file of the same name wrote in --out",
    )
    g.add_argument(
        "--json",
        action="store_true",
        help="print the report (as in <design>.report.json) to stdout instead of the summary",
    )
    g.add_argument(
        "--progress",
        action="store_true",
        help="progress bar (fraction, ETA) on stderr even when it is not a terminal or with --quiet; "
        "by default it is drawn only on a terminal",
    )
    g.add_argument("--quiet", action="store_true", help="print nothing on success")
    add_memory_flag(g)
    g.set_defaults(func=cmd_generate)
