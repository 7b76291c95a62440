"""The part set's files as a library call: every part a shop makes (cup flexspline, generator plug, rigid gear,
deformed assemblies) as DXF, SVG, STL, 3MF and STEP, with ``<design>_parts.json``, written in one atomic batch
after everything is built. ``wgcad parts`` wraps it: flags, the bar, printing."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...atomic import atomic_batch, check_writable_dir
from ...errors import DesignError, GeometryError
from ...report.parts import part_report, parts_document
from ..formats.json_text import json_text
from ..formats.registry import FORMATS, Drawing
from ..formats.step import step_bytes
from ..parts import build_parts
from ..parts.kernel import require
from ..parts.title import title_layer

__all__ = ["FORMATS", "PartFiles", "write_part_files"]


@dataclass(slots=True)
class PartFiles:
    """What :func:`write_part_files` did: the parts built, the report document (``<design>_parts.json``) and the
    files written (the report last)."""

    parts: list
    report: dict
    files: list


def write_part_files(
    drive, sizes, source, out, *, formats=FORMATS, dxf_style: str = "arcs", generator_angles_deg=(), progress=None
) -> PartFiles:
    """Build the parts of ``drive`` with the sizes ``sizes`` (:func:`wgcad.design.parts.part_sizes`) and write
    them in ``formats`` into the folder ``out``, named after the design file ``source``.

    Every mesh and STEP solid is built before the folder is touched (a mesh that is not watertight is a
    :class:`~wgcad.errors.GeometryError`, nothing written; STEP without build123d a
    :class:`~wgcad.errors.DependencyError` naming the extra); ``progress(fraction, stage)`` follows the work."""
    tick = progress or (lambda f, stage: None)
    chosen = list(formats)
    for name in chosen:
        if name not in FORMATS:
            raise DesignError("formats", f"'{name}' is not a format (choose from {', '.join(FORMATS)})")
    fmts = [f for name, f in FORMATS.items() if name in chosen]  # written in the registry's order
    sources = {f.source for f in fmts}
    out, stem = Path(out), Path(source).stem
    parts = build_parts(drive, sizes, style=dxf_style, tol=drive.tol, generator_angles_deg=list(generator_angles_deg))
    # what the chosen formats are written from, each part's: its drawing, mesh (also for the set's 3MF) and solid
    step_parts = [p for p in parts if not p.name.startswith("assembly")] if "solid" in sources else []
    if step_parts:
        require()  # a missing CAD extra is said before anything is built
    n_mesh = len(parts) if {"mesh", "set"} & sources else 0
    # the steps weighted by what they cost (a mesh or a DXF/SVG/STL file is one unit, a STEP solid and its text
    # each several): the progress moves with the work
    total = 1.0 + 1.0 * n_mesh + 8.0 * len(step_parts) + 0.5 * len(parts)
    done = 1.0
    tick(done / total, "meshes" if n_mesh else "solids")
    # build everything before the output folder is touched
    items = {"drawing": {}, "mesh": {}, "solid": {}}
    if "drawing" in sources:
        for p in parts:
            if p.layers:  # with its title block (what, from which design, units, scale, material)
                title = title_layer(p.name, drive.design, source, p.layers, drive.tol)
                items["drawing"][p.name] = Drawing([*p.layers, title], f"{drive.design.drive.name}: {p.name}")
    for p in parts if n_mesh else ():
        tick(done / total, f"mesh: {p.name}")
        m = p.mesh()
        if not m.is_watertight:
            raise GeometryError(f"{p.name}: mesh is not watertight")
        items["mesh"][p.name] = m
        done += 1.0
    for p in step_parts:
        tick(done / total, f"STEP solid: {p.name}")
        solid = p.solid()
        done += 4.0
        tick(done / total, f"STEP text: {p.name}")
        items["solid"][p.name] = step_bytes(solid)
        done += 4.0
    check_writable_dir(out)
    files = []
    report = parts_document(drive, sizes, source, dxf_style, chosen)
    with atomic_batch() as batch:

        def target(name):
            path = out / name
            files.append(path)
            return batch.temp_path(path)

        for p in parts:
            tick(done / total, f"files: {p.name}")
            report["parts"][p.name] = part_report(p)
            for f in fmts:
                if f.source != "set" and p.name in items[f.source]:
                    f.write(target(f"{stem}_{p.name}.{f.name}"), items[f.source][p.name])
            done += 0.5
        for f in fmts:
            if f.source == "set":
                f.write(target, stem, parts, items["mesh"])
        # named by the design, as every other file here: two designs can share a folder
        report["files"] = [f.name for f in files] + [f"{stem}_parts.json"]
        Path(target(f"{stem}_parts.json")).write_text(json_text(report) + "\n")
    tick(1.0, "done")
    return PartFiles(parts, report, files)
