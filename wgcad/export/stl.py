"""Extruded ring solids and deterministic binary STL export, in mm.

A ring between two outlines that each see the origin once (most gear rings)
is triangulated by :mod:`wgcad.export.zipper` (a sort; 2-10 ms a gear); any
other region by manifold3d (35-90 ms a gear, imported only then).

The solids are :class:`wgcad.export.mesh.Mesh` (numpy arrays); trimesh is
not imported (0.33 s of every ``generate``), the tests read the STL back
with it.
"""

from __future__ import annotations

import math
import os

import numpy as np
import shapely

from wgcad.atomic import atomic_write
from wgcad.errors import GeometryError
from wgcad.export.mesh import Mesh
from wgcad.export.rings import clean_outline
from wgcad.export.zipper import extruded_ring
from wgcad.plane import signed_area

__all__ = ["ring_solid", "stl_bytes", "write_stl"]

#: Largest relative difference allowed between the cross-section area
#: manifold3d builds and the shapely area of the input polygon. manifold3d
#: snaps coordinates to a 1e-8 mm grid (Clipper2), which moves a 40k-vertex
#: 80 mm gear outline's area by ~2e-12 relative; anything above 1e-9 means
#: a contour was dropped or merged (e.g. a wrongly oriented outline).
AREA_REL_TOL = 1e-9

#: First 80 bytes of every STL file (padded with NUL). Must not start with
#: "solid", or some readers take the binary file for ASCII.
STL_HEADER = b"wgcad binary STL, units mm"


def _ring(points, what: str) -> np.ndarray:
    # repeated points are removed before extrusion: trimesh's extruder silently
    # builds broken meshes from them and manifold3d would merge them anyway
    return clean_outline(points, what=what, too_few=GeometryError)


def ring_solid(outer, holes=(), height: float = 1.0) -> Mesh:
    """Extrude a 2D region with holes along +z into a closed solid.

    Parameters
    ----------
    outer : (N, 2) float array_like
        Outer boundary in mm, closing edge implicit or explicit; either
        orientation is accepted (it is made counter-clockwise).
    holes : sequence of (M, 2) float array_like
        Hole boundaries inside ``outer``, either orientation (each is made
        clockwise, as manifold3d's positive fill rule needs).
    height : float
        Extrusion height in mm; the solid spans ``0 <= z <= height``.

    Returns
    -------
    Mesh
        Watertight, consistently outward-oriented mesh with float64
        vertices, ``(V, 3)`` vertices and ``(F, 3)`` faces. Its volume equals
        the polygon area times ``height`` to ~1e-12 relative. A zipper
        triangulation keeps the outlines' vertices exactly (adding some on
        their edges); manifold3d snaps them to a 1e-8 mm grid.

    Raises
    ------
    ValueError
        If an array has the wrong shape or ``height`` is not a positive
        finite number.
    GeometryError
        If the region is not a valid polygon (self-intersections, holes
        crossing the outer boundary or each other), or the extruded mesh is
        not watertight or not a volume.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    >>> circle = np.c_[np.cos(t), np.sin(t)]
    >>> m = ring_solid(10 * circle, [5 * circle], height=2.0)
    >>> bool(m.is_watertight), m.bounds[:, 2].tolist()
    (True, [0.0, 2.0])
    """
    height = float(height)
    if not (math.isfinite(height) and height > 0):
        raise ValueError(f"height must be a positive finite number of mm, got {height}")
    outer = _ring(outer, "outer boundary")
    if signed_area(outer) < 0:
        outer = outer[::-1]
    ring_holes = []
    for k, hole in enumerate(holes):
        h = _ring(hole, f"hole {k}")
        if signed_area(h) > 0:
            h = h[::-1]
        ring_holes.append(h)

    polygon = shapely.Polygon(outer, ring_holes)
    if not polygon.is_valid:
        raise GeometryError(f"ring cross-section is not a valid polygon ({shapely.is_valid_reason(polygon)})")

    if len(ring_holes) == 1:
        # a gear ring: a zipper triangulation where both outlines see the origin once (module note of
        # wgcad.export.zipper), closed and outward by construction; manifold3d for the others
        mesh = extruded_ring(outer, ring_holes[0][::-1], height)
        if mesh is not None:
            cap = mesh.faces[: len(mesh.faces) // 4]  # the bottom cap, reversed
            t = mesh.vertices[cap]
            u, v = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
            area = -0.5 * float(np.sum(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]))
            if abs(area - polygon.area) > AREA_REL_TOL * polygon.area:
                raise GeometryError(
                    f"ring triangulation area {area:.9g} mm^2 differs from the polygon's {polygon.area:.9g} mm^2"
                )
            return mesh
    import manifold3d  # only where the zipper does not apply (0.01 s to import)

    section = manifold3d.CrossSection([outer, *ring_holes], manifold3d.FillRule.Positive)
    if abs(section.area() - polygon.area) > AREA_REL_TOL * polygon.area:
        raise GeometryError(
            f"ring cross-section area {section.area():.9g} mm^2 differs from the polygon's "
            f"{polygon.area:.9g} mm^2 (manifold3d dropped or merged a contour)"
        )
    solid = manifold3d.Manifold.extrude(section, height)
    # to_mesh64: float64 vertices; to_mesh() rounds to float32 (~4 um at 80 mm).
    mesh64 = solid.to_mesh64()
    vertices = np.asarray(mesh64.vert_properties, dtype=np.float64)[:, :3]
    faces = np.asarray(mesh64.tri_verts, dtype=np.int64)
    mesh = Mesh(vertices, faces)
    if not mesh.is_watertight:
        raise GeometryError("extruded ring is not watertight")
    if not mesh.is_volume:
        raise GeometryError("extruded ring is not a volume (inconsistent winding or self-intersecting)")
    return mesh


def stl_bytes(mesh: Mesh) -> bytes:
    """Binary STL content of a mesh, deterministic for the same mesh.

    Parameters
    ----------
    mesh : Mesh
        ``(V, 3)`` vertices in mm, ``(F, 3)`` faces.

    Returns
    -------
    bytes
        ``84 + 50 F`` bytes: the :data:`STL_HEADER`, the triangle count,
        then per triangle its float32 normal and three float32 vertices.
        STL is float32: a coordinate between 64 and 128 mm moves by up to
        half the float32 spacing 2**-17 mm, i.e. 3.8 um.
    """
    return mesh.stl_bytes(STL_HEADER)


def write_stl(path: str | os.PathLike, mesh: Mesh) -> None:
    """Write a mesh as binary STL, atomically.

    Parameters
    ----------
    path : str or path-like
        Output file; the folder is created if missing.
    mesh : Mesh
        The solid, in mm.

    Raises
    ------
    OutputError
        When the file cannot be written (``path`` is then unchanged).
    """
    atomic_write(path, stl_bytes(mesh))
