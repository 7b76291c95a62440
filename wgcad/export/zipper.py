"""The extruded solid of a ring between two outlines that each see the origin once, triangulated by a zipper.

A gear ring is the region between a circle and a tooth outline. When both
outlines are strictly monotone in polar angle about the origin, merging
their vertices by angle triangulates the region between them ("zipper"):
each step advances one outline by one vertex and makes one triangle with the
other outline's current vertex. That costs a sort (a few ms for 18,000
vertices) where a general constrained triangulation (manifold3d) costs
40-80 ms per gear.

The triangulation is accepted only when every triangle is strictly
positively oriented. That is enough for it to be valid: the triangles form a
combinatorial annulus whose boundary runs once along each (simple, nested)
outline, so the number of triangles covering a point, counted with their
orientation, is the outlines' winding number about it - one inside the ring,
none outside; with every orientation positive, every point of the ring lies
in exactly one triangle. An outline that turns back in angle (an undercut
seen from the centre) or a triangle of zero area gives ``None``, and the
caller triangulates otherwise.
"""

from __future__ import annotations

import numpy as np

from wgcad.export.mesh import Mesh

__all__ = ["zipper_triangles", "extruded_ring"]


def _polar(points: np.ndarray):
    """The closed outline started at its least polar angle, and its angles, if they increase strictly round once."""
    ang = np.arctan2(points[:, 1], points[:, 0])
    start = int(np.argmin(ang))
    points = np.roll(points, -start, axis=0)
    ang = np.roll(ang, -start)
    closed = np.append(ang, ang[0] + 2.0 * np.pi)
    if not np.all(np.diff(closed) > 0.0):
        return None
    return points, closed


def _zip(po, ao, pi, ai):
    """The zipper's triangles (indices into ``po`` then ``pi``), their doubled signed areas, and whether each
    is an outer step (apex on the inner outline) - for outlines started at their least angle (:func:`_polar`)."""
    m, n = len(po), len(pi)
    # step k of an outline goes from its vertex k to k + 1 (the last back to 0), at the angle it reaches
    order = np.argsort(np.concatenate([ao[1:], ai[1:]]), kind="stable")
    is_outer = order < m
    done_outer = np.cumsum(is_outer) - is_outer  # outer steps before each event
    done_inner = np.cumsum(~is_outer) - ~is_outer
    o0, i0 = done_outer % m, done_inner % n
    o1, i1 = (done_outer + 1) % m, (done_inner + 1) % n
    tri = np.where(
        is_outer[:, None],
        np.stack([o0, o1, m + i0], axis=1),
        np.stack([m + i1, m + i0, o0], axis=1),
    )
    t = np.concatenate([po, pi])[tri]
    u, v = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    return tri, u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], is_outer


def _split(p, ap, edges, angles):
    """Outline ``p`` (angles ``ap``, closed) with a vertex added on each of ``edges`` where a ray at one of
    ``angles`` crosses it; ``None`` if the angles then fail to increase strictly."""
    a0 = ap[0]
    angles = a0 + np.mod(angles - a0, 2.0 * np.pi)
    e = np.searchsorted(ap, angles, side="right") - 1
    inside = np.isin(e, edges) & (angles > ap[np.minimum(e, len(ap) - 1)]) & (e < len(p))
    angles, e = angles[inside], e[inside]
    if len(e) == 0:
        return None
    order = np.lexsort((angles, e))
    angles, e = angles[order], e[order]
    a, b = p[e], p[(e + 1) % len(p)]
    ray = np.column_stack([np.cos(angles), np.sin(angles)])
    d = b - a
    t = -(ray[:, 0] * a[:, 1] - ray[:, 1] * a[:, 0]) / (ray[:, 0] * d[:, 1] - ray[:, 1] * d[:, 0])
    # a ray through (or within rounding of) an end of the edge meets a vertex already there
    keep = (t > 1e-9) & (t < 1.0 - 1e-9)
    if not keep.any():
        return None
    q = a[keep] + t[keep, None] * d[keep]
    out = np.insert(p, e[keep] + 1, q, axis=0)
    return _polar(out)


def zipper_triangles(outer: np.ndarray, inner: np.ndarray, rounds: int = 3):
    """Triangles of the region between two counter-clockwise outlines, ``inner`` inside ``outer``.

    Where a triangle comes out not positive (an outline vertex that cannot
    see a far one: a sparse bore circle below steep tooth flanks), the two
    edges beside its apex get a vertex where each ray through a vertex of
    the other outline in their angle crosses them, and the zipper runs
    again: between two outlines that have vertices at the same angles every
    step is a convex quadrilateral, which either diagonal splits into two
    positive triangles. The added vertices lie on the edges, so the region
    is the same.

    Parameters
    ----------
    outer, inner : (M, 2), (N, 2) float arrays
        Closed outlines (closing edge implicit), counter-clockwise.
    rounds : int
        How many times edges are split before giving up.

    Returns
    -------
    (M' + N', 2) points, (M' + N', 3) int triangles, M' or None
        The points are the outer outline (with vertices added, ``M'`` of
        them) then the inner one, each started at its least polar angle;
        the triangles index them, counter-clockwise. ``None`` when an
        outline is not strictly monotone in polar angle or triangles stay
        not strictly positive (see the module's note).
    """
    a = _polar(np.asarray(outer, dtype=np.float64))
    b = _polar(np.asarray(inner, dtype=np.float64))
    if a is None or b is None:
        return None
    (po, ao), (pi, ai) = a, b
    for _ in range(rounds + 1):
        tri, area2, is_outer = _zip(po, ao, pi, ai)
        bad = area2 <= 0.0
        if not bad.any():
            return np.concatenate([po, pi]), tri, len(po)
        m, n = len(po), len(pi)
        apex = tri[bad, 2]
        inner_apex = apex[is_outer[bad]] - m
        outer_apex = apex[~is_outer[bad]]
        if len(inner_apex):
            got = _split(pi, ai, np.concatenate([inner_apex, (inner_apex - 1) % n]), ao[:-1])
            if got is None:
                return None
            pi, ai = got
        if len(outer_apex):
            got = _split(po, ao, np.concatenate([outer_apex, (outer_apex - 1) % m]), ai[:-1])
            if got is None:
                return None
            po, ao = got
    return None


def extruded_ring(outer: np.ndarray, inner: np.ndarray, height: float) -> Mesh | None:
    """The solid ``0 <= z <= height`` over the ring between two counter-clockwise outlines, or ``None``.

    ``None`` where :func:`zipper_triangles` gives none. The mesh is closed and
    outward-oriented by construction: the caps are the zipper's triangles
    (the bottom one reversed), the walls two triangles per outline edge.
    """
    got = zipper_triangles(outer, inner)
    if got is None:
        return None
    pts, tri, m = got
    k = len(pts)
    vertices = np.concatenate([np.column_stack([pts, np.zeros(k)]), np.column_stack([pts, np.full(k, float(height))])])
    j = np.arange(k)
    # next vertex along the own outline: outer 0..m-1, inner m..k-1
    nxt = np.where(j < m, (j + 1) % m, m + (j - m + 1) % (k - m))
    outer_edge = j < m
    # wall of edge j -> nxt: outward is right of an outer edge, left of an inner (hole) edge
    wall_a = np.where(outer_edge[:, None], np.stack([j, nxt, k + nxt], 1), np.stack([nxt, j, k + j], 1))
    wall_b = np.where(outer_edge[:, None], np.stack([j, k + nxt, k + j], 1), np.stack([nxt, k + j, k + nxt], 1))
    faces = np.concatenate([tri[:, ::-1], tri + k, wall_a, wall_b])
    return Mesh(vertices, faces)
