"""The files of a drive as a library call: the gears' DXF and STL, the deformed assembly's DXF and PNG at given
generator angles, ``<design>.report.json`` and the folder's manifest, written in one atomic batch.
``wgcad generate`` wraps it: flags, the bar, printing (docs/models.md, appendix A for the exported outlines)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...atomic import atomic_batch, check_target
from ...errors import OutputError
from ...placement.imperfect import Imperfections
from ...plane import circle_polygon
from ...profiles.band import gear_band_outline
from ...report import drive_report
from ...report.deformed import deformed_scene
from ...report.notes import not_modelled
from ..formats.dxf import DxfLayer, write_dxf
from ..formats.json_text import json_text
from ..formats.stl import ring_solid, write_stl
from ..pictures.drive import assembly_png
from .manifest import Manifest, manifest_name

__all__ = ["DriveFiles", "angle_tag", "report_name", "planned_names", "write_drive_files"]

# Relative cost of the steps, for a progress bar (on D1 a deformed-state picture costs ~100 DXF files, an STL
# ~10); only the bar's pace uses them.
_COST = {"design": 0.3, "dxf": 0.3, "stl": 2.0, "angle_dxf": 1.0, "angle_png": 15.0, "report": 0.2}


def report_name(stem: str) -> str:
    """``<design>.report.json``: one report per design, so designs can share an output folder."""
    return f"{stem}.report.json"


def angle_tag(deg: float) -> str:
    """The file-name tag of a generator angle in degrees: ``p015_000`` for +15 deg, ``m002_500`` for -2.5 deg."""
    # angles closer than the tag's 1e-3 deg resolution share a file name: keep 6 decimals then
    tag = f"{deg:+08.3f}"
    if abs(round(deg, 3) - deg) > 1e-9:
        tag = f"{deg:+011.6f}"
    return tag.replace("+", "p").replace("-", "m").replace(".", "_")


def planned_names(stem: str, angles_deg, stl: bool) -> list[str]:
    """Every file name a run writes for the design ``stem``, its manifest included."""
    names = [f"{stem}.dxf", report_name(stem), manifest_name(stem)]
    names += [f"{stem}_flexspline.stl", f"{stem}_rigid.stl"] if stl else []
    names += [f"{stem}_phi{angle_tag(deg)}.{ext}" for deg in angles_deg for ext in ("dxf", "png")]
    return names


@dataclass(slots=True)
class DriveFiles:
    """What :func:`write_drive_files` did: the report document, the files written (report last), the previous
    run's files it removed, and the names it kept because they changed since that run wrote them."""

    report: dict
    files: list
    removed: list
    kept: list


def _judge_targets(out: Path, source: Path, angles, stl: bool, force: bool):
    """The folder's manifest for the design, once every file the run writes is judged writable."""
    manifest = Manifest(out, source.stem, source)
    manifest.check_collision(force)
    # every file this run will write is judged before any work: a device, FIFO, folder or link in the way stops
    # the run now, not after minutes of computing
    for name in planned_names(source.stem, angles, stl):
        check_target(out / name)
        if (out / name).exists() and os.path.samefile(out / name, source):
            raise OutputError(f"{out / name}: is the design file itself; it would be overwritten (give another --out)")
    return manifest


def _report(drive) -> tuple[dict, object]:
    """The drive's report document and the errors its deformed assembly is drawn with (None: perfect parts)."""
    design = drive.design
    rep = drive_report(drive)
    # the deformed assembly places the parts with their errors (rigid gear fixed: docs/models.md 6.2); the gears'
    # own DXF and STL stay nominal, the part a shop makes
    imp = None
    if design.imperfections.any and design.drive.fixed == "rigid":
        imp = Imperfections.from_spec(design.imperfections)
    rep["not_modelled"] = not_modelled(design, "generate", imperfections=imp is not None)
    if imp is not None:
        rep["imperfections"] = (
            "the deformed-assembly DXF/PNG (--generator-angle) place every tooth with its [imperfections]; "
            "the gears' DXF and STL are the nominal parts"
        )
    return rep, imp


def _gear_solid(drive, gear, outline, rim: float):
    """The gear's solid over the face width: its exported outline and its rim circle, whichever is inside."""
    rim_circle = circle_polygon(rim, drive.tol)
    if rim < min(gear.r_a, gear.r_f):  # bore inside the teeth
        return ring_solid(outline, [rim_circle], drive.design.drive.face_width)
    return ring_solid(rim_circle, [outline], drive.design.drive.face_width)  # teeth inside a ring


def _deformed_layers(drive, scene) -> list:
    """The deformed assembly's DXF layers at one generator angle."""
    return [
        DxfLayer("RIGID", outlines=(scene["rigid_outline"],), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
        DxfLayer("FLEXSPLINE_DEFORMED", outlines=(scene["flex_outline"],), color=5),
        DxfLayer("FLEXSPLINE_RIM_DEFORMED", outlines=(scene["flex_rim"],), color=5),
        DxfLayer("NEUTRAL_LINE", outlines=(scene["neutral"],), color=3),
    ]


def _deformed_png(drive, scene, deg: float, imperfect: bool) -> bytes:
    """The deformed assembly's picture at the generator angle ``deg``."""
    d = drive.design
    return assembly_png(
        scene,
        f"{d.drive.name}: generator at {deg:g} deg counter-clockwise from +x "
        f"({d.generator.law} law, W0 = {d.w0:.3f} mm"
        + (", generator's centre section" if drive.coned else "")
        + (", parts with their [imperfections])" if imperfect else ")"),
        entry_deg=scene["entry_deg"],
    )


def write_drive_files(
    drive, source, out, *, angles_deg=(), stl: bool = True, force: bool = False, progress=None
) -> DriveFiles:
    """Write the files of ``drive`` (read from the design file ``source``) into the folder ``out``.

    Every target is judged before any work (a device, FIFO, folder or link in the way, or the design file itself,
    is an :class:`~wgcad.errors.OutputError`); a folder holding another design file's run of the same name is
    refused unless ``force``. Nothing is written unless all is: one atomic batch, which also removes the previous
    run's files this run does not write again. ``progress(fraction, stage)`` follows the work."""
    tick = progress or (lambda f, stage: None)
    out, source = Path(out), Path(source)
    angles = [float(a) for a in angles_deg]
    stem = source.stem
    total = (
        _COST["design"]
        + _COST["dxf"]
        + (2 * _COST["stl"] if stl else 0)
        + len(angles) * (_COST["angle_dxf"] + _COST["angle_png"])
        + _COST["report"]
    )
    done = 0.0

    def step(cost, next_stage):
        nonlocal done
        done += cost
        tick(done / total, next_stage)

    manifest = _judge_targets(out, source, angles, stl, force)
    step(_COST["design"], "DXF")
    gears = {"flexspline": (drive.flex, drive.flex_rim_radius), "rigid": (drive.rigid, drive.rigid_rim_radius)}
    # the exported outlines run in a symmetric band around the exact curves (docs/models.md, appendix A): chords
    # through curve points would make every convex flank thin, every space narrow
    band = {name: gear_band_outline(gear) for name, (gear, _) in gears.items()}
    layers = [
        DxfLayer("FLEXSPLINE", outlines=(band["flexspline"],), color=5),
        DxfLayer("FLEXSPLINE_RIM", circles=((0.0, 0.0, drive.flex_rim_radius),), color=5),
        DxfLayer("RIGID", outlines=(band["rigid"],), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
    ]
    rep, imp = _report(drive)
    files = []
    with atomic_batch() as batch:
        path = out / f"{stem}.dxf"
        write_dxf(batch.temp_path(path), layers)
        files.append(path)
        step(_COST["dxf"], "STL")
        if stl:
            for name, (gear, rim) in gears.items():
                tick(done / total, f"STL {name}")
                mesh = _gear_solid(drive, gear, band[name], rim)
                rep[name]["solid_volume_mm3"] = round(float(mesh.volume), 4)
                path = out / f"{stem}_{name}.stl"
                write_stl(batch.temp_path(path), mesh)
                files.append(path)
                step(_COST["stl"], f"STL {name}")
        for deg in angles:
            tick(done / total, f"{deg:g} deg: DXF")
            scene = deformed_scene(drive, np.deg2rad(deg), imp)
            path = out / f"{stem}_phi{angle_tag(deg)}.dxf"
            write_dxf(batch.temp_path(path), _deformed_layers(drive, scene))
            files.append(path)
            step(_COST["angle_dxf"], f"{deg:g} deg: picture")
            path = out / f"{stem}_phi{angle_tag(deg)}.png"
            Path(batch.temp_path(path)).write_bytes(_deformed_png(drive, scene, deg, imp is not None))
            files.append(path)
            step(_COST["angle_png"], f"{deg:g} deg: picture")
        tick(done / total, "report")
        rep["generator_angles_deg"] = angles
        report_path = out / report_name(stem)
        rep["files"] = [p.name for p in files] + [report_path.name]
        # no timings in the report: the same design must give byte-identical files
        Path(batch.temp_path(report_path)).write_text(json_text(rep) + "\n")
        files.append(report_path)
        # the previous run's files for this design that this run does not write again go with the commit
        stale, kept = manifest.stale_files(p.name for p in files)
        for p in stale:
            batch.remove_on_commit(p)
        Path(batch.temp_path(out / manifest_name(stem))).write_text(manifest.document(batch.pairs))
    tick(1.0, "done")
    return DriveFiles(rep, files, stale, kept)
