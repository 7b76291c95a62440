"""The one description of every part: closed plane loops swept straight along z (or ruled between two sections) into
walls, closed by plane caps; the mesh is derived here, the solid by :mod:`wgcad.export.parts.kernel`.

Every part of the set is such a body: toothed rings, the cup on its ring, the
flanged rigid gear, the plug, the deformed assembly's prisms. A *loop* holds
one closed outline twice: its exact curves (lines and tangent arcs fitted to
the tooth curves and to the plug's offset law curve, whole circles) for the
solid, and its polygon within the chord tolerance of the same curves for the
mesh. A *wall* sweeps a loop from ``z0`` to ``z1`` (a face-modified ring: ruled
between the loops of its two end sections, docs/models.md 13.4), a *cap* is the
plane face at a wall's end bounded by the loops it names. No surface is
intersected with another, so neither the solid nor the mesh needs a boolean.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from wgcad.errors import GeometryError
from wgcad.plane import signed_area

__all__ = ["Loop", "Wall", "Cap", "Body", "path_loop", "circle_loop", "polygon_loop", "prism", "mesh"]


@dataclasses.dataclass(frozen=True)
class Loop:
    """One closed plane outline: its exact curves and the mesh's polygon of them (mm, any direction).

    ``kind``: ``"path"`` (lines and arcs: segment starts ``vertices``, ``bulges`` = tan(theta / 4) as
    :mod:`wgcad.export.formats.arcs` stores them) or ``"circle"`` (centre ``vertices[0]``, ``radius``). ``polygon``: the same outline within the chord tolerance, no
    repeated vertex. ``role`` names the faces its wall makes (``teeth``, ``bore``, ``flange``, ...).
    """

    kind: str
    vertices: np.ndarray
    polygon: np.ndarray
    role: str
    bulges: np.ndarray | None = None
    radius: float = 0.0

    @property
    def ccw(self) -> bool:
        """Whether the loop runs counter-clockwise (its polygon's signed area > 0)."""
        return signed_area(self.polygon) > 0


def path_loop(path, polygon, role: str) -> Loop:
    """A loop of lines and arcs (an :class:`~wgcad.export.formats.arcs.ArcPath`) and its polygon (the band of the same
    curves, or the path's own vertices for a polygon outline)."""
    return Loop("path", np.asarray(path.vertices, float), _clean(polygon), role, np.asarray(path.bulges, float))


def polygon_loop(points, role: str) -> Loop:
    """A loop of straight segments (closing edge implicit): the polygon is its own exact outline."""
    pts = _clean(points)
    return Loop("path", pts, pts, role, np.zeros(len(pts)))


def circle_loop(radius: float, tol: float, role: str, cx: float = 0.0, cy: float = 0.0) -> Loop:
    """A whole circle; its polygon the inscribed one within ``tol`` (:func:`~wgcad.export.parts.solids.circle_points`)."""
    from .solids import circle_points

    return Loop("circle", np.array([[cx, cy]], float), circle_points(radius, tol, cx, cy), role, radius=float(radius))


def _clean(points) -> np.ndarray:
    from wgcad.export.formats.rings import clean_outline

    return clean_outline(np.asarray(points, dtype=float))


@dataclasses.dataclass(frozen=True)
class Wall:
    """The side faces of ``loop`` swept from ``z0`` up to ``z1`` (or ruled to ``top`` at ``z1``: corresponding
    segments and polygon vertices); ``inside``: the material lies inside the loop (an outer boundary), else outside
    (a hole)."""

    loop: Loop
    z0: float
    z1: float
    inside: bool
    top: Loop | None = None

    def at(self, z: float) -> Loop:
        """The wall's loop at its end ``z``."""
        if z == self.z0:
            return self.loop
        if z == self.z1:
            return self.top if self.top is not None else self.loop
        raise GeometryError(f"a cap at z = {z} mm on a wall from {self.z0} to {self.z1} mm")


@dataclasses.dataclass(frozen=True)
class Cap:
    """The plane face at ``z``, outward normal +z if ``up``, bounded by the walls ``bounds = ((wall index, region
    inside that wall's loop), ...)`` that end or start there."""

    z: float
    up: bool
    bounds: tuple
    role: str = "end"


@dataclasses.dataclass(frozen=True)
class Body:
    """One solid: its walls and the caps that close them."""

    walls: tuple
    caps: tuple

    def __post_init__(self):
        for c in self.caps:
            for i, _ in c.bounds:
                self.walls[i].at(c.z)  # raises unless the wall ends or starts at the cap
        for w in self.walls:
            if not w.z1 > w.z0:
                raise GeometryError(f"a wall from z = {w.z0} to {w.z1} mm")
            if w.top is not None and w.top.polygon.shape != w.loop.polygon.shape:
                raise GeometryError("a ruled wall needs sections of corresponding vertices")


def prism(outer: Loop, holes, z0: float, z1: float, role: str = "end") -> Body:
    """The solid between ``z0`` and ``z1`` over the region inside ``outer`` and outside every loop of ``holes``."""
    walls = (Wall(outer, z0, z1, True), *(Wall(h, z0, z1, False) for h in holes))
    bounds = tuple((i, i == 0) for i in range(len(walls)))
    return Body(walls, (Cap(z0, False, bounds, role), Cap(z1, True, bounds, role)))


def _ring(poly: np.ndarray, material_left: bool) -> np.ndarray:
    """Vertex order that puts the material on the left seen from +z (the index permutation)."""
    idx = np.arange(len(poly))
    return idx if (signed_area(poly) > 0) == material_left else idx[::-1]


def mesh(body: Body):
    """The triangle mesh of a body (:class:`wgcad.export.formats.mesh.Mesh`): every wall a band of quads between its polygon
    at both ends, every cap triangulated from the same vertices (manifold3d), so each edge is shared by exactly two
    triangles: watertight by construction."""
    import manifold3d

    from ..formats.mesh import Mesh

    verts, faces, rings = [], [], []
    at = 0
    for w in body.walls:
        p0 = w.loop.polygon
        p1 = w.top.polygon if w.top is not None else p0
        order = _ring(p0, w.inside)  # the top section of a ruled wall runs the same way (corresponding vertices)
        n = len(p0)
        verts += [np.column_stack([p0[order], np.full(n, w.z0)]), np.column_stack([p1[order], np.full(n, w.z1)])]
        b, t = at + np.arange(n), at + n + np.arange(n)
        j = np.roll(np.arange(n), -1)
        faces += [np.column_stack([b, b[j], t[j]]), np.column_stack([b, t[j], t])]
        rings.append({w.z0: (b, p0[order]), w.z1: (t, p1[order])})
        at += 2 * n
    for c in body.caps:
        ids, polys = [], []
        for i, region_inside in c.bounds:
            idx, pts = rings[i][c.z]
            if region_inside != body.walls[i].inside:  # the region lies right of the material-left ring: flip it
                idx, pts = idx[::-1], pts[::-1]
            ids.append(idx)
            polys.append(pts)
        # triangulate's triangles run counter-clockwise for an outer boundary counter-clockwise and holes clockwise:
        # every ring here is the region's boundary with the region on its left
        tri = np.concatenate(ids)[np.asarray(manifold3d.triangulate(polys), dtype=np.int64)]
        faces.append(tri if c.up else tri[:, ::-1])
    out = Mesh(np.concatenate(verts), np.concatenate(faces))
    if not out.is_watertight or not out.is_volume:
        raise GeometryError("part mesh is not a closed volume")
    return out
