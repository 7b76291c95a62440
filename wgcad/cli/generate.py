"""``wgcad generate``: DXF, STL, <design>.report.json and deformed-state pictures of a design."""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from .common import EXIT_OK, add_memory_flag, angle_tag, angles_deg, circle, epilog, out_dir, positive_float

__all__ = ["register", "cmd_generate", "report_name"]


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
    from ..report.notes import not_modelled

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
            from ..report.deformed import deformed_scene
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
        epilog=epilog(),
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
