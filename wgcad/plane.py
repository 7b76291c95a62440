"""Small plane-geometry helpers shared by the profiles, the placement and the exporters (numpy only)."""

from __future__ import annotations

import numpy as np

__all__ = ["signed_area", "circle_polygon", "rotate", "relative_pose"]


def signed_area(pts) -> float:
    """Signed area (mm^2) of the closed polygon ``(N, 2)`` (closing edge implicit): positive counter-clockwise (shoelace)."""
    p = np.asarray(pts, dtype=float)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def rotate(v, angle) -> np.ndarray:
    """Vectors ``v (K, 2)`` turned counter-clockwise by ``angle`` (rad; a scalar or one per vector)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=-1)


def relative_pose(rot_a, shift_a, rot_b, shift_b):
    """Pose of copies of A (``rot_a (K,)``, ``shift_a (K, 2)``) in the frames of copies of B: rotation and shift."""
    return rot_a - rot_b, rotate(shift_a - shift_b, -rot_b)


def circle_polygon(radius: float, tol: float) -> np.ndarray:
    """``(N, 2)`` points of the circle of ``radius`` (mm) about the origin, counter-clockwise from +x, its chords
    within ``tol`` (mm) of the arc (at least 64 points)."""
    step = 2.0 * np.arccos(max(-1.0, 1.0 - tol / radius))
    n = max(64, int(np.ceil(2 * np.pi / step)))
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
