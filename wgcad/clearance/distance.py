"""Signed clearance between pairs of congruent polygons: distance when apart, minus the penetration depth when overlapping."""

from __future__ import annotations

import numpy as np
import shapely

from ..placement import transform
from ..plane import relative_pose
from .threads import in_halves

__all__ = ["Template", "outline_distance", "overlap_depth", "signed_clearance", "pair_distance"]

#: below this many pairs one thread measures them all (handing half to the helper costs ~30 us)
SPLIT_MIN = 64


def pair_distance(a, b) -> np.ndarray:
    """``shapely.distance(a, b)`` of arrays of geometries, on two cores where there are two and many pairs.

    GEOS releases the GIL, so half the pairs measured on a helper thread
    while this one measures the other half take about half the time. The figures are the same
    (the same GEOS call on each pair).
    """
    if np.size(a) < SPLIT_MIN:
        return shapely.distance(a, b)
    pairs = np.broadcast_arrays(np.asarray(a, dtype=object), np.asarray(b, dtype=object))
    return in_halves(shapely.distance, tuple(pairs), least=SPLIT_MIN)


class Template:
    """A polygon whose rigid copies are queried many times: prepared once for point tests.

    Parameters
    ----------
    local : (N, 2) float
        Counter-clockwise outline, closed implicitly.
    """

    def __init__(self, local: np.ndarray):
        self.local = np.ascontiguousarray(local, dtype=float)
        self.local.setflags(write=False)
        self.polygon = shapely.Polygon(self.local)
        self.ring = self.polygon.exterior
        shapely.prepare(self.polygon)
        shapely.prepare(self.ring)

    def depth_of(self, pts: np.ndarray) -> np.ndarray:
        """For points ``(K, N, 2)`` in this template's frame: how far each pair's deepest point lies inside, ``(K,)``."""
        K, N, _ = pts.shape
        flat = pts.reshape(-1, 2)
        ins = shapely.contains_xy(self.polygon, flat[:, 0], flat[:, 1])
        out = np.zeros(K * N)
        if ins.any():
            out[ins] = self.boundary_distance(flat[ins])
        return out.reshape(K, N).max(axis=1)

    def boundary_distance(self, pts: np.ndarray) -> np.ndarray:
        """Distance ``(M,)`` of points ``(M, 2)`` to the outline (:func:`outline_distance`)."""
        return outline_distance(self.local, pts)[0]


def outline_distance(outline: np.ndarray, pts: np.ndarray):
    """Distance ``(M,)`` of points ``(M, 2)`` to a closed outline ``(N, 2)``, point against every edge in numpy;
    with the nearest edge ``(M,)`` (edge i runs from vertex i to i + 1) and the position along it ``(M,)`` in [0, 1].

    The tooth outlines have tens of edges: one vectorised pass beats a GEOS
    call per point (and its point objects) by an order of magnitude.
    Points are taken in chunks so memory stays bounded.
    """
    a = np.asarray(outline, dtype=float)
    d = np.roll(a, -1, axis=0) - a
    l2 = np.maximum((d**2).sum(-1), 1e-300)
    ax, ay, dx, dy = a[:, 0], a[:, 1], d[:, 0], d[:, 1]
    M = len(pts)
    out = np.empty(M)
    edge = np.empty(M, dtype=int)
    along = np.empty(M)
    # ~40,000 point-edge pairs a chunk: the temporaries stay in the cache (twice as fast as 400,000)
    step = max(1, 40_000 // len(a))
    rows = np.arange(min(step, M))
    for i in range(0, M, step):
        p = pts[i : i + step]
        rx = p[:, 0, None] - ax
        ry = p[:, 1, None] - ay
        u = rx * dx
        u += ry * dy
        u /= l2
        np.clip(u, 0.0, 1.0, out=u)
        rx -= u * dx  # the offset from the nearest point of each edge
        ry -= u * dy
        rx *= rx
        ry *= ry
        rx += ry
        j = rx.argmin(axis=1)
        r = rows[: len(p)]
        out[i : i + step] = np.sqrt(rx[r, j])
        edge[i : i + step] = j
        along[i : i + step] = u[r, j]
    return out, edge, along


def overlap_depth(a: Template, rot_a, shift_a, b: Template, rot_b, shift_b) -> np.ndarray:
    """Penetration depth ``(K,)`` of pairs known to touch or overlap (their distance is 0): the deepest vertex of
    either polygon inside the other, measured to the other's boundary (:func:`signed_clearance`)."""
    r, t = relative_pose(rot_a, shift_a, rot_b, shift_b)
    depth_ab = b.depth_of(transform(a.local, r, t))  # vertices of A inside B
    r, t = relative_pose(rot_b, shift_b, rot_a, shift_a)
    depth_ba = a.depth_of(transform(b.local, r, t))  # vertices of B inside A
    return np.maximum(depth_ab, depth_ba)


def signed_clearance(
    a: Template, rot_a, shift_a, b: Template, rot_b, shift_b, b_geoms=None, area: bool = False, a_geoms=None
):
    """Signed clearance of pairs of rigid copies ``(A_k, B_k)``: > 0 apart, < 0 overlapping (minus the depth).

    The depth of an overlap is the largest distance by which a vertex of one
    polygon lies inside the other, measured to the other's boundary. When
    the overlap region holds a vertex of either polygon (the lens-shaped
    overlaps of teeth pressed into each other) its deepest point relative to
    the other boundary is such a vertex, and the figure is exact for the
    polygons and within the chord tolerance of the curves. Two polygons that
    cross like a "+" with no vertex inside the other read 0 (contact): not
    reachable by teeth sampled to 1 um, and recorded as an expected failure
    in tests/test_stability.py.

    Parameters
    ----------
    a, b : Template
    rot_a, rot_b : (K,) float
    shift_a, shift_b : (K, 2) float
        Poses of the copies of each pair.
    b_geoms, a_geoms : (K,) shapely geometries, optional
        The copies of ``b`` (``a``) if already built (e.g. static rigid
        teeth, or flexspline teeth measured against two neighbours).
    area : bool
        Also return the overlap areas.

    Returns
    -------
    clearance : (K,) float, mm
    overlap_area : (K,) float, mm^2 (with ``area=True``)
    """
    rot_a = np.atleast_1d(np.asarray(rot_a, dtype=float))
    rot_b = np.broadcast_to(np.asarray(rot_b, dtype=float), rot_a.shape)
    shift_a = np.atleast_2d(np.asarray(shift_a, dtype=float))
    shift_b = np.broadcast_to(np.asarray(shift_b, dtype=float), shift_a.shape)
    if a_geoms is None:
        a_geoms = shapely.polygons(transform(a.local, rot_a, shift_a))
    if b_geoms is None:
        b_geoms = shapely.polygons(transform(b.local, rot_b, shift_b))
    d = pair_distance(a_geoms, b_geoms)
    over = np.nonzero(d == 0.0)[0]
    out = d.copy()
    if over.size:
        out[over] = -overlap_depth(a, rot_a[over], shift_a[over], b, rot_b[over], shift_b[over])
    if not area:
        return out
    ov_area = np.zeros(len(d))
    if over.size:
        ov_area[over] = shapely.area(shapely.intersection(a_geoms[over], b_geoms[over]))
    return out, ov_area
