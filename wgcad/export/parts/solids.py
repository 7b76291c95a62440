"""Small geometry of the parts: circles as polygons within the chord tolerance, bolt circles, a manifold3d solid as a
float64 mesh."""

from __future__ import annotations

import math

import numpy as np

from wgcad.errors import GeometryError

from ..formats.mesh import Mesh

__all__ = ["n_segments", "circle_points", "to_mesh", "bolt_circle"]


def n_segments(radius: float, tol: float) -> int:
    """Polygon sides that keep a circle of ``radius`` within ``tol`` (inscribed), at least 64."""
    return max(64, int(math.ceil(math.pi / math.acos(max(-1.0, 1.0 - tol / radius)))))


def circle_points(radius: float, tol: float, cx: float = 0.0, cy: float = 0.0) -> np.ndarray:
    """Counter-clockwise inscribed polygon ``(n, 2)`` of a circle."""
    n = n_segments(radius, tol)
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([cx + radius * np.cos(t), cy + radius * np.sin(t)])


def to_mesh(m):
    """float64 :class:`wgcad.export.formats.mesh.Mesh` of a manifold (``to_mesh64``: ``to_mesh`` would round to float32)."""
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
