"""The part set of a drive: cup flexspline, wave-generator plug, rigid gear with flange, deformed assembly; each as DXF layers and one recipe its solid and mesh derive from.

A :class:`Part` holds what every exporter needs: its 2D drawing
(:class:`~wgcad.export.formats.dxf.DxfLayer` list, top view, mm), its recipe
(:mod:`~wgcad.export.parts.recipe`: loops of the exact curves swept into
walls, closed by caps), from which the OpenCASCADE solid (build123d, built
only when STEP or an object is asked for) and the mesh both derive, and the
volume expected from its 2D areas so every export can be checked against it.
"""

from __future__ import annotations

from wgcad.sector.built import built_gear

from . import assembly, bodies
from .part import Part

__all__ = ["Part", "build_parts"]


def build_parts(drive, sizes, style: str = "arcs", tol: float | None = None, generator_angles_deg=()) -> list:
    """Every part of a drive (and one deformed assembly per generator angle).

    Parameters
    ----------
    drive : wgcad.drive.Drive
    sizes : wgcad.design.parts.PartSizes
    style : {"arcs", "polyline"}
        How tooth outlines are drawn in the DXF layers (STEP always uses arcs).
    tol : float, optional
        Chord tolerance (mm); default ``drive.tol``.
    generator_angles_deg : sequence of float
        Assembly meshes at these generator angles.

    Returns
    -------
    list of Part
    """
    tol = drive.tol if tol is None else tol
    sectored = None
    if drive.design.sectors.active:
        # a sectored design's rigid gear is the sectored one, teeth at the heights the design builds (once:
        # the part set wrote the plain gear of z_rigid teeth without a word)
        sectored = built_gear(drive.design, drive=drive)
    out = [
        bodies.flexspline(drive, sizes, style, tol),
        bodies.plug(drive, sizes, tol),
        bodies.rigid(drive, sizes, style, tol, sectored=sectored),
    ]
    for deg in generator_angles_deg:
        out.append(assembly.deformed_assembly(drive, sizes, deg, tol))
    return out
