"""Mesh building blocks for the parts (manifold3d, float64 out): prisms with holes, solids of revolution, bolt-hole cylinders."""

from __future__ import annotations

import math

import numpy as np

from wgcad.plane import signed_area

__all__ = ["n_segments", "circle_points", "prism_m", "revolve_m", "holes_m", "to_mesh", "ccw"]


def n_segments(radius: float, tol: float) -> int:
    """Polygon sides that keep a circle of ``radius`` within ``tol`` (inscribed), at least 64."""
    return max(64, int(math.ceil(math.pi / math.acos(max(-1.0, 1.0 - tol / radius)))))


def circle_points(radius: float, tol: float, cx: float = 0.0, cy: float = 0.0) -> np.ndarray:
    """Counter-clockwise inscribed polygon ``(n, 2)`` of a circle."""
    n = n_segments(radius, tol)
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([cx + radius * np.cos(t), cy + radius * np.sin(t)])


def ccw(pts: np.ndarray, positive: bool = True) -> np.ndarray:
    """The polygon oriented counter-clockwise (``positive``) or clockwise."""
    return pts if (signed_area(pts) > 0) == positive else pts[::-1]


def prism_m(outer, holes, z0: float, z1: float):
    """manifold3d prism of a polygon region between ``z0`` and ``z1``."""
    import manifold3d

    from wgcad.export.rings import clean_outline

    polys = [ccw(clean_outline(outer))] + [ccw(clean_outline(h), positive=False) for h in holes]
    sec = manifold3d.CrossSection(polys, manifold3d.FillRule.Positive)
    return manifold3d.Manifold.extrude(sec, z1 - z0).translate((0.0, 0.0, z0))


def loft_m(outer0, outer1, z0: float, z1: float):
    """manifold3d solid lofted from the outline ``outer0`` at ``z0`` to ``outer1`` at ``z1``.

    The outlines have the same vertices in the same order (one outline whose teeth move linearly with z,
    docs/models.md 13.4); each side face joins vertex ``i`` of both, the caps are triangulated separately.
    """
    import manifold3d

    a, b = np.asarray(outer0, dtype=float), np.asarray(outer1, dtype=float)
    if a.shape != b.shape:
        raise ValueError("lofted outlines need the same vertex count")
    if signed_area(a) < 0:
        a, b = a[::-1], b[::-1]
    n = len(a)
    verts = np.concatenate([np.column_stack([a, np.full(n, z0)]), np.column_stack([b, np.full(n, z1)])])
    i = np.arange(n)
    j = (i + 1) % n
    tris = np.concatenate(
        [
            np.column_stack([i, j, n + j]),
            np.column_stack([i, n + j, n + i]),
            np.asarray(manifold3d.triangulate([a]), dtype=np.int64)[:, ::-1],  # the bottom cap faces -z
            n + np.asarray(manifold3d.triangulate([b]), dtype=np.int64),
        ]
    )
    out = manifold3d.Manifold(
        manifold3d.Mesh64(vert_properties=np.ascontiguousarray(verts), tri_verts=tris.astype(np.uint32))
    )
    if out.status() != manifold3d.Error.NoError:
        raise ValueError(f"lofted solid is not a closed manifold ({out.status()})")
    return out


def revolve_m(rz, n: int):
    """manifold3d solid of revolution about z of a closed (r, z) polygon, ``n`` segments."""
    import manifold3d

    sec = manifold3d.CrossSection([ccw(np.asarray(rz, dtype=float))], manifold3d.FillRule.Positive)
    return manifold3d.Manifold.revolve(sec, n)


def holes_m(holes, z0: float, z1: float, tol: float):
    """Union of axial cylinders ``[(cx, cy, d)]`` reaching 1 mm beyond ``z0..z1`` (to subtract)."""
    out = None
    for cx, cy, d in holes:
        c = prism_m(circle_points(d / 2.0, tol, cx, cy), [], z0 - 1.0, z1 + 1.0)
        out = c if out is None else out + c
    return out


def to_mesh(m):
    """float64 :class:`wgcad.export.mesh.Mesh` of a manifold (``to_mesh64``: ``to_mesh`` would round to float32)."""
    from wgcad.errors import GeometryError

    from ..mesh import Mesh

    mesh64 = m.to_mesh64()
    v = np.asarray(mesh64.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(mesh64.tri_verts, dtype=np.int64)
    mesh = Mesh(v, f)
    if len(f) == 0 or not mesh.is_watertight or not mesh.is_volume:
        raise GeometryError("part mesh is empty or not a closed volume")
    return mesh


def bolt_circle(diameter: float, count: int, hole: float, phase: float = 0.0) -> list:
    """``[(cx, cy, hole)]`` of ``count`` holes evenly on a bolt circle, the first at angle ``phase``."""
    return [
        (
            0.5 * diameter * math.cos(phase + 2 * math.pi * k / count),
            0.5 * diameter * math.sin(phase + 2 * math.pi * k / count),
            hole,
        )
        for k in range(count)
    ]
