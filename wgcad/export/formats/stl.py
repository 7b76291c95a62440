"""Extruded ring solids (manifold3d) and deterministic binary STL export, in mm.

The solids are :class:`wgcad.export.formats.mesh.Mesh` (numpy arrays, see there why
not trimesh's); the tests read the STL back with trimesh.
"""

from __future__ import annotations

import math
import os

import numpy as np
import shapely

from wgcad.atomic import atomic_write
from wgcad.errors import GeometryError
from wgcad.export.formats.mesh import Mesh
from wgcad.export.formats.rings import clean_outline
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
        the polygon area times ``height`` to ~1e-12 relative; manifold3d
        snaps the vertices to a 1e-8 mm grid.

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

    import manifold3d

    section = manifold3d.CrossSection([outer, *ring_holes], manifold3d.FillRule.Positive)
    area = section.area()
    if abs(area - polygon.area) > AREA_REL_TOL * polygon.area:
        raise GeometryError(
            f"ring cross-section area {area:.9g} mm^2 differs from the polygon's "
            f"{polygon.area:.9g} mm^2 (manifold3d dropped or merged a contour)"
        )
    solid = manifold3d.Manifold.extrude(section, height)
    if solid.status() != manifold3d.Error.NoError:
        raise GeometryError(f"extruded ring is not a manifold ({solid.status().name})")
    if abs(solid.volume() - area * height) > AREA_REL_TOL * area * height:
        raise GeometryError(
            f"extruded ring volume {solid.volume():.9g} mm^3 is not its section's area times {height:g} mm"
        )
    # to_mesh64: float64 vertices; to_mesh() rounds to float32 (~4 um at 80 mm).
    mesh64 = solid.to_mesh64()
    return Mesh(
        np.asarray(mesh64.vert_properties, dtype=np.float64)[:, :3], np.asarray(mesh64.tri_verts, dtype=np.int64)
    )


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
