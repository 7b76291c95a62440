"""Biarc fit of exact curve pieces within a chord tolerance, and the measured deviation of the arcs from the curves (numpy only).

A fitted path is a closed sequence of circular arcs (or straight segments)
stored the way a DXF LWPOLYLINE stores it: vertices and, per vertex, the
*bulge* ``tan(theta / 4)`` of the segment that starts there (``theta`` the
signed included angle, positive counter-clockwise; 0 for a straight line).

Each smooth piece is split recursively in its parameter until one biarc
(two arcs meeting tangentially, docs/models.md 12.1) per sub-interval lies
within the tolerance of the curve; the sub-intervals share the curve's
tangent at their ends, so the arcs are tangent wherever the curve is smooth
and meet at an angle only where the pieces do (tooth corners).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wgcad.plane import rotate

__all__ = [
    "ArcPath",
    "fit_pieces",
    "fit_gear",
    "arc_points",
    "arc_deviation",
    "bulge_centres",
    "segment_tangents",
    "path_area",
    "CurvePiece",
    "fit_closed_curve",
]

#: Curve points checked per biarc while fitting (the curve->arc distance).
#: The independent check, :func:`arc_deviation`, samples the arcs instead.
N_CHECK = 24

#: Deepest recursion (2**-40 of a piece's parameter range): only reached on
#: a broken piece, which then raises instead of looping.
MAX_DEPTH = 40


@dataclass(frozen=True, slots=True)
class ArcPath:
    """A closed path of arcs, as an LWPOLYLINE stores it.

    Attributes
    ----------
    vertices : (n, 2) float
        Segment start points; segment ``i`` runs to vertex ``i + 1`` (the
        last one back to vertex 0).
    bulges : (n,) float
        ``tan(theta / 4)`` of each segment, ``theta`` its signed included
        angle (positive counter-clockwise); 0 for a straight segment.
    source : (n, 4) float
        ``(piece index, t_start, t_end, turn)``: the exact curve each
        segment replaces is piece ``index`` between those parameters, turned
        by ``turn`` (rad) about the origin (for the deviation check).
    end : (2,) float or None
        ``None`` for a closed path; else the end point of the last segment.
    """

    vertices: np.ndarray
    bulges: np.ndarray
    source: np.ndarray
    end: np.ndarray | None = None

    @property
    def ends(self) -> np.ndarray:
        """End point of every segment ``(n, 2)``."""
        out = np.roll(self.vertices, -1, axis=0)
        if self.end is not None:
            out[-1] = self.end
        return out

    def rotated(self, angle: float) -> ArcPath:
        """The same path turned by ``angle`` about the origin (bulges are invariant)."""
        c, s = np.cos(angle), np.sin(angle)
        v = self.vertices
        rot = lambda p: np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)  # noqa: E731
        src = self.source.copy()
        src[:, 3] += angle
        return ArcPath(rot(v), self.bulges, src, None if self.end is None else rot(self.end))

    @property
    def n_arcs(self) -> int:
        """Segments with a non-zero bulge."""
        return int(np.count_nonzero(self.bulges))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.hypot(v[..., 0], v[..., 1])[..., None]


def _tangent(piece, t: float, forward: float) -> np.ndarray:
    """Unit tangent in the direction of travel (``forward`` = sign of dt); second derivative at a cusp."""
    d = piece.deriv(np.array([t]))[0] * forward
    scale = max(1e-300, float(np.hypot(*(piece.point(np.array([piece.t1]))[0] - piece.point(np.array([piece.t0]))[0]))))
    if np.hypot(*d) <= 1e-9 * scale / max(abs(piece.t1 - piece.t0), 1e-300):
        # cusp (e.g. a cycloid's start on the pitch circle): P ~ P0 + P'' dt^2 / 2 leaves along +P'' either way
        d2 = piece.deriv2(np.array([t]))[0]
        # leaving the cusp (start of the piece) the path runs along +P''; arriving at it, along -P''
        d = d2 if abs(t - piece.t0) <= abs(t - piece.t1) else -d2
    return _unit(d)


def _arc_from(p, tan, q):
    """Bulge of the arc leaving ``p`` along unit ``tan`` and ending at ``q``."""
    c = q - p
    theta = 2.0 * np.arctan2(tan[0] * c[1] - tan[1] * c[0], tan[0] * c[0] + tan[1] * c[1])
    return float(np.tan(theta / 4.0))


def _biarc(p0, t0, p1, t1):
    """Equal-leg biarc from ``p0`` (tangent ``t0``) to ``p1`` (tangent ``t1``): joint point and two bulges."""
    v = p1 - p0
    tt = t0 + t1
    vt = float(v @ tt)
    vv = float(v @ v)
    denom = 2.0 * (1.0 - float(t0 @ t1))
    if denom < 1e-12:  # parallel tangents
        vt1 = float(v @ t1)
        d = vv / (4.0 * vt1) if abs(vt1) > 1e-300 else 0.5 * np.sqrt(vv)
    else:
        d = (-vt + np.sqrt(vt * vt + denom * vv)) / denom
    joint = 0.5 * ((p0 + d * t0) + (p1 - d * t1))
    b0 = _arc_from(p0, t0, joint)
    # second arc: run it backwards from p1 with tangent -t1 to the joint, then flip the sign
    b1 = -_arc_from(p1, -t1, joint)
    return joint, b0, b1


def bulge_centres(start: np.ndarray, end: np.ndarray, bulge: np.ndarray):
    """Centres ``(n, 2)``, radii ``(n,)`` and included angles ``(n,)`` of bulge segments (radius inf for lines)."""
    start, end, bulge = np.atleast_2d(start), np.atleast_2d(end), np.atleast_1d(bulge)
    chord = end - start
    c = np.hypot(chord[:, 0], chord[:, 1])
    theta = 4.0 * np.arctan(bulge)
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = c / (2.0 * np.abs(np.sin(theta / 2.0)))
        # centre: chord midpoint + normal (left of the chord for ccw arcs) * signed distance
        h = (c / 2.0) / np.tan(theta / 2.0)
        normal = np.stack([-chord[:, 1], chord[:, 0]], axis=-1) / c[:, None]
        centre = 0.5 * (start + end) + normal * h[:, None]
    straight = bulge == 0
    radius = np.where(straight, np.inf, radius)
    centre[straight] = np.nan
    return centre, radius, theta


def arc_points(start, end, bulge, n: int) -> np.ndarray:
    """``n`` points evenly spaced along each bulge segment, ends included: ``(m, n, 2)``."""
    start, end, bulge = np.atleast_2d(start), np.atleast_2d(end), np.atleast_1d(bulge)
    s = np.linspace(0.0, 1.0, n)
    centre, radius, theta = bulge_centres(start, end, bulge)
    straight = bulge == 0
    out = start[:, None, :] + (end - start)[:, None, :] * s[None, :, None]
    if np.any(~straight):
        k = ~straight
        a0 = np.arctan2(start[k, 1] - centre[k, 1], start[k, 0] - centre[k, 0])
        ang = a0[:, None] + theta[k, None] * s[None, :]
        out[k] = centre[k, None, :] + radius[k, None, None] * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    return out


#: samples of a piece's dense polyline for the arc-to-curve check of the fitter
DENSE = 257


def _dist_to_polyline(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance of points ``(n, 2)`` from the polyline ``(p, 2)`` (its segments), ``(n,)``."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    ap = pts[:, None, :] - a[None, :, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(L2 > 0, np.einsum("nij,ij->ni", ap, ab) / L2, 0.0)
    u = np.clip(u, 0.0, 1.0)
    d = ap - u[..., None] * ab[None, :, :]
    return np.hypot(d[..., 0], d[..., 1]).min(axis=1)


def _dist_to_segments(pts, start, end, bulge):
    """Distance of points ``(m, 2)`` to the nearest of a few bulge segments (exact point-arc distance)."""
    best = np.full(len(pts), np.inf)
    for a, b, g in zip(start, end, bulge):
        if g == 0:
            ab = b - a
            s = np.clip(((pts - a) @ ab) / float(ab @ ab), 0.0, 1.0)
            d = np.hypot(*(pts - a - s[:, None] * ab).T)
        else:
            centre, radius, theta = bulge_centres(a, b, np.array([g]))
            c, r, th = centre[0], radius[0], theta[0]
            a0 = np.arctan2(a[1] - c[1], a[0] - c[0])
            ang = np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0])
            rel = (ang - a0) * np.sign(th)
            rel = np.mod(rel, 2 * np.pi)
            inside = rel <= abs(th)
            d_circle = np.abs(np.hypot(pts[:, 0] - c[0], pts[:, 1] - c[1]) - r)
            d_ends = np.minimum(np.hypot(*(pts - a).T), np.hypot(*(pts - b).T))
            d = np.where(inside, d_circle, d_ends)
        best = np.minimum(best, d)
    return best


def _fit_piece(piece, index: int, tol: float, out_v, out_b, out_s):
    t_a, t_b = float(piece.t0), float(piece.t1)
    fwd = 1.0 if t_b >= t_a else -1.0
    if piece.kind == "line":
        out_v.append(piece.point(np.array([t_a]))[0])
        out_b.append(0.0)
        out_s.append((index, t_a, t_b, 0.0))
        return
    if piece.kind == "arc":  # exact: one bulge segment (split in two above a half turn)
        theta = t_b - t_a
        n = int(np.ceil(abs(theta) / np.pi)) or 1
        ts = np.linspace(t_a, t_b, n + 1)
        pts = piece.point(ts)
        for k in range(n):
            out_v.append(pts[k])
            out_b.append(float(np.tan((ts[k + 1] - ts[k]) / 4.0)))
            out_s.append((index, ts[k], ts[k + 1], 0.0))
        return
    stack = [(t_a, t_b, 0)]
    while stack:
        a, b, depth = stack.pop()
        pa, pb = piece.point(np.array([a, b]))
        ta, tb = _tangent(piece, a, fwd), _tangent(piece, b, fwd)
        joint, b0, b1 = _biarc(pa, ta, pb, tb)
        ts = np.linspace(a, b, N_CHECK + 2)[1:-1]
        dev = _dist_to_segments(piece.point(ts), np.array([pa, joint]), np.array([joint, pb]), np.array([b0, b1]))
        if dev.max() <= tol and np.all(np.abs([b0, b1]) < 1.0):
            # and the other way: the written arcs may stray from the curve between the curve's
            # samples (near a cycloid's cusp the curvature is unbounded); measure arc points
            # against a dense polyline of the curve, which can only overstate their distance
            # by the polyline's own sagitta (taken off the tolerance)
            arcs = arc_points(np.array([pa, joint]), np.array([joint, pb]), np.array([b0, b1]), N_CHECK + 2).reshape(
                -1, 2
            )
            dense = piece.point(np.linspace(a, b, DENSE))
            sag = _dist_to_polyline(
                piece.point(0.5 * (np.linspace(a, b, DENSE)[1:] + np.linspace(a, b, DENSE)[:-1])), dense
            ).max()
            back = _dist_to_polyline(arcs, dense).max()
            if back > tol - sag:
                dev = np.append(dev, back)
        if dev.max() <= tol and np.all(np.abs([b0, b1]) < 1.0):
            # the joint's parameter is not known exactly; the two halves share [a, b] as their source
            out_v.extend([pa, joint])
            out_b.extend([b0, b1])
            out_s.extend([(index, a, b, 0.0), (index, a, b, 0.0)])
            continue
        if depth >= MAX_DEPTH:
            raise ValueError(f"piece {index} ({piece.kind}) cannot be fitted by arcs within {tol:g} mm")
        m = 0.5 * (a + b)
        stack.append((m, b, depth + 1))  # LIFO: [a, m] comes out first
        stack.append((a, m, depth + 1))


def fit_pieces(pieces, tol: float, closed: bool = True) -> ArcPath:
    """Fit a closed C0 path of exact pieces by arcs within ``tol``.

    Parameters
    ----------
    pieces : sequence of Piece
        Exact pieces (:mod:`wgcad.profiles.pieces`), each with ``kind``,
        ``t0``, ``t1``, vectorised ``point``, ``deriv``, ``deriv2``; the end
        of each is the start of the next and the last ends where the first
        starts. Arcs are copied exactly, lines stay lines, other curves are
        biarc-fitted.
    tol : float
        Largest distance (mm) between a curve and its arcs.
    closed : bool
        False for an open path: it then ends at the last piece's end.

    Returns
    -------
    ArcPath
    """
    out_v: list = []
    out_b: list = []
    out_s: list = []
    for i, p in enumerate(pieces):
        _fit_piece(p, i, tol, out_v, out_b, out_s)
    end = None if closed else pieces[-1].point(np.array([pieces[-1].t1]))[0]
    return ArcPath(
        np.asarray(out_v, dtype=float),
        np.asarray(out_b, dtype=float),
        np.asarray(out_s, dtype=float).reshape(-1, 4),
        end,
    )


def arc_deviation(path: ArcPath, pieces, n_per_arc: int = 64, newton_steps: int = 8) -> np.ndarray:
    """Largest distance of each written segment from its exact curve, mm ``(n,)``.

    Samples ``n_per_arc`` points along every segment (ends included) and finds
    each point's foot on the segment's source curve: the nearest of 65
    curve samples over the segment's parameter range widened by a quarter on
    each side (clamped to the piece), then a golden-section search between
    its neighbours (no curvature needed: it is unbounded at a cycloid's
    cusp). The foot found is a point on the curve, so the distance is an
    upper bound of the true one (it agrees with a 2-million-point brute
    force to 1e-10 mm on a cusped epicycloid).
    """
    v = path.vertices
    ends = path.ends
    q = arc_points(v, ends, path.bulges, n_per_arc)  # (n, k, 2)
    # into the frame of the source piece
    c, sn = np.cos(-path.source[:, 3])[:, None], np.sin(-path.source[:, 3])[:, None]
    q = np.stack([c * q[..., 0] - sn * q[..., 1], sn * q[..., 0] + c * q[..., 1]], axis=-1)
    dev = np.zeros(len(v))
    s = np.linspace(0.0, 1.0, n_per_arc)
    idx = path.source[:, 0].astype(int)
    for i in np.unique(idx):
        sel = np.nonzero(idx == i)[0]
        pc = pieces[i]
        lo_p, hi_p = sorted((float(pc.t0), float(pc.t1)))
        ta, tb = path.source[sel, 1], path.source[sel, 2]
        # the two halves of a biarc share [a, b]: start each half in its own half
        t = ta[:, None] + (tb - ta)[:, None] * s[None, :]
        pts = q[sel]
        w = 0.25 * np.abs(tb - ta)[:, None]
        lo = np.maximum(np.minimum(ta, tb)[:, None] - w, lo_p)
        hi = np.minimum(np.maximum(ta, tb)[:, None] + w, hi_p)
        tt = t.ravel()
        qq = pts.reshape(-1, 2)
        lo, hi = np.broadcast_to(lo, t.shape).ravel(), np.broadcast_to(hi, t.shape).ravel()
        # coarse start: nearest of 65 curve samples of the segment's window (near a cycloid's
        # cusp the curvature is unbounded and a coarse start leaves Newton far from the foot)
        grid = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, 65)[None, :]
        g = pc.point(grid.ravel()).reshape(grid.shape + (2,))
        k = np.argmin(np.hypot(*(g - qq[:, None, :]).transpose(2, 0, 1)), axis=1)
        # then a golden-section search between the grid neighbours: the distance is unimodal there,
        # and unlike Newton it needs no curvature (unbounded at a cycloid's cusp)
        rows = np.arange(len(tt))
        a_ = grid[rows, np.maximum(k - 1, 0)]
        b_ = grid[rows, np.minimum(k + 1, grid.shape[1] - 1)]
        gr = 0.5 * (np.sqrt(5.0) - 1.0)

        def dist(x):
            return np.hypot(*(pc.point(x) - qq).T)

        c_, d_ = b_ - gr * (b_ - a_), a_ + gr * (b_ - a_)
        fc, fd = dist(c_), dist(d_)
        for _ in range(newton_steps + 40):
            left = fc < fd
            b_ = np.where(left, d_, b_)
            a_ = np.where(left, a_, c_)
            d_new = np.where(left, c_, a_ + gr * (b_ - a_))
            c_new = np.where(left, b_ - gr * (b_ - a_), d_)
            fd, fc = np.where(left, fc, dist(d_new)), np.where(left, dist(c_new), fd)
            c_, d_ = c_new, d_new
        tt = 0.5 * (a_ + b_)
        d = np.hypot(*(pc.point(tt) - qq).T).reshape(t.shape)
        dev[sel] = d.max(axis=1)
    return dev


def fit_gear(gear, tol: float, offset: float = 0.0) -> ArcPath:
    """The whole toothed boundary of a gear as one closed arc path, in the order of ``gear.outline``.

    One pitch (``gear.pieces``) is fitted once and turned ``z`` times by
    ``k 2 pi / z + phase`` (bulges do not change under rotation); the
    segment sources index ``gear.pieces`` with the turn of their tooth.
    ``offset`` (mm): every pitch moved that far out along its tooth's centre
    line first (a face-modified section, docs/models.md 13.4); the last
    segment of a pitch then ends on the next pitch's moved first vertex (at
    the middle of the root, where the pitches part by ``2 offset sin(pi/z)``),
    and the sources name the unmoved curves.
    """
    pieces = list(gear.pieces)
    one = fit_pieces(pieces, tol, closed=False)
    if offset:
        move = np.array([float(offset), 0.0])
        one = ArcPath(one.vertices + move, one.bulges, one.source, None if one.end is None else one.end + move)
    turned = [one.rotated(k * gear.pitch_angle + gear.spec.phase) for k in range(gear.spec.z)]
    return ArcPath(
        np.concatenate([t.vertices for t in turned]),
        np.tile(one.bulges, gear.spec.z),
        np.concatenate([t.source for t in turned]),
    )


def segment_tangents(path: ArcPath) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents at the start and at the end of every segment, in the direction of travel ``(n, 2)`` each."""
    v, e = path.vertices, path.ends
    chord = _unit(e - v)
    half = 2.0 * np.arctan(path.bulges)  # theta / 2

    turn = rotate

    return turn(chord, -half), turn(chord, half)


def path_area(path_or_vertices, bulges=None) -> float:
    """Signed area enclosed by a closed bulge path (positive counter-clockwise), mm^2.

    Shoelace area of the vertices plus, per arc, the circular segment
    between chord and arc, ``r^2 (theta - sin theta) / 2`` (signed with
    ``theta``): exact for arcs, no sampling.
    """
    if bulges is None:
        v, b = path_or_vertices.vertices, path_or_vertices.bulges
    else:
        v, b = np.asarray(path_or_vertices, dtype=float), np.asarray(bulges, dtype=float)
    e = np.roll(v, -1, axis=0)
    shoelace = 0.5 * float(np.sum(v[:, 0] * e[:, 1] - e[:, 0] * v[:, 1]))
    c = np.hypot(*(e - v).T)
    theta = 4.0 * np.arctan(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(b != 0, c / (2.0 * np.abs(np.sin(theta / 2.0))), 0.0)
    seg = 0.5 * r * r * (theta - np.sin(theta))
    return shoelace + float(np.sum(np.where(b != 0, seg, 0.0)))


class CurvePiece:
    """A smooth curve given by a vectorised function ``f(t) -> (n, 2)`` on ``[t0, t1]``, as a piece :func:`fit_pieces`
    takes: the derivatives by central differences of step ``h`` (the fit checks its arcs against ``f`` itself, so
    the derivatives only steer where the arcs go)."""

    kind = "curve"

    def __init__(self, f, t0: float, t1: float, h: float = 1e-6):
        self.f, self.t0, self.t1, self.h = f, float(t0), float(t1), float(h)

    def point(self, t):
        return self.f(np.asarray(t, dtype=float))

    def deriv(self, t):
        t = np.asarray(t, dtype=float)
        return (self.f(t + self.h) - self.f(t - self.h)) / (2.0 * self.h)

    def deriv2(self, t):
        t = np.asarray(t, dtype=float)
        return (self.f(t + self.h) - 2.0 * self.f(t) + self.f(t - self.h)) / (self.h * self.h)


def fit_closed_curve(f, tol: float, period: float = 2.0 * np.pi, pieces: int = 8) -> ArcPath:
    """Tangent arcs within ``tol`` of a smooth closed curve ``f(t)``, ``t`` in ``[0, period)`` (e.g. a wave-generator
    plug's outline against its angle), as ``pieces`` pieces joined end to end."""
    edges = np.linspace(0.0, period, pieces + 1)
    return fit_pieces([CurvePiece(f, a, b) for a, b in zip(edges[:-1], edges[1:])], tol)
