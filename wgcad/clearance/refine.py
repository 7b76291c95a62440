"""Signed clearance of two placed teeth on their exact curves, refined from the polygon answer (docs/models.md 5).

The polygons find where two teeth come closest; this module computes the
figure on the analytic pieces (:mod:`wgcad.profiles.pieces`). The signed
clearance of teeth A and B is ``min(min_s sd_B(P_A(s)), min_t sd_A(P_B(t)))``
with ``sd_X`` the signed distance to X's boundary (> 0 outside its
material): the distance when apart, minus the deepest penetration of either
boundary into the other when overlapping - the polygon engine's definition
(:func:`wgcad.clearance.distance.signed_clearance`), on the curves. For
teeth apart both minima are the one distance between the boundaries, so
the second side is measured only where the polygons say the teeth can
touch or overlap, or where a row of the first side stopped short of a
stationary point or a corner (its figure is then only an upper bound).

Pairs the polygons say are apart are measured first by one batch for all
of them (:mod:`wgcad.clearance.apart`: the distance between the curves by a
joint Newton iteration from the same seeds); the pairs it leaves unsolved,
and those that can touch or overlap, by the iteration below. Both are
seeded from B's vertices too wherever B's vertex distances come within the
margin of A's (:func:`_b_side`): the polygons' distance is attained at a
vertex of one of them, and where it is B's corner against the middle of a
long edge of A, A's vertices there can lie farther than the margin above
it and A's seeds miss the basin.

How: every polygon vertex lies on a piece with a known parameter. The
vertices whose polygon signed distance is within a margin of the polygon
minimum seed a Newton iteration on ``f(s) = sd_B(P_A(s))`` for the vertex's
piece against every piece of the other tooth that can hold the nearest
point: the nearest point ``Q(t)`` follows by projection (its own Newton),
and ``f'``, ``f''`` come from the reduced derivatives of ``|P(s) - Q(t)|^2/2``
(the envelope theorem). Where ``f''`` is not positive the step aims at the
piece's end and continues on the next piece from there; each step tries
the full Newton step and three shorter ones in one vectorised call and
keeps the best that does not raise ``f``. Each end point ``P(s)`` is then
measured exactly against the whole other boundary (projection on every
piece): every candidate is a true signed distance of a true curve point, so
the smallest is an upper bound of the exact figure, reached when a seed lies
in the basin of the true extremum (the polygon's own extremum is within a
vertex spacing of it). A row stops when a full Newton step improves ``f``
by less than 1e-9 mm; tests/test_refine.py checks the figures against
polygons at 0.0001 um chords to :data:`wgcad.constants.REFINE_TOL`.
"""

from __future__ import annotations

import numpy as np
import shapely

from ..plane import relative_pose, rotate
from .apart import apart_distance, vertex_seeds
from .distance import outline_distance
from .exact import ExactTooth, curv_h, point_signed_distance

__all__ = ["ExactTooth", "refine_pairs", "apart_pairs", "point_signed_distance"]

_NEWTON_STEPS = 40
#: neighbours of a local minimum of the vertex distances also seeded (a coarse polygon's extremum can lie a
#: vertex away from the curve's); the second neighbours once seeded too doubled the rows for no figure changed
#: (4e-11 um over every template's audit calls), and tests/test_exact.py checks 10 um chords
_NEAR = (1,)
#: fractions of the Newton step tried at once (a vectorised line search)
_FRACTIONS = np.array([1.0, 0.25, 1.0 / 16.0, 1.0 / 128.0])
#: a row whose full Newton step improves its value by less than this (mm) is converged: the step
#: after a Newton step is far smaller still, and even linear convergence at rate 0.9 leaves < 1e-8 mm,
#: 100 times below :data:`wgcad.constants.REFINE_TOL`
_DONE = 1e-9
#: below this distance (mm) the curves are taken to cross: the second derivative of the signed value
#: is computed by dividing by it, so it is not trusted there
_CROSS = 1e-10


def _vertex_sd(A: ExactTooth, polyA: np.ndarray, polyB: np.ndarray, geomB, rot, shift):
    """Polygon signed distance ``(K, nv)`` of A's period vertices (A placed in B's frame) to B's polygon, with the
    nearest edge of B's polygon and the position on it (:func:`wgcad.clearance.distance.outline_distance`)."""
    K = len(rot)
    nv = A.n_vert
    va = np.einsum("kij,nj->kni", _rotmat(rot), polyA[A.vert_index]) + shift[:, None, :]  # (K, nv, 2)
    flat = va.reshape(-1, 2)
    d, edge, along = outline_distance(polyB, flat)
    inside = shapely.contains_xy(geomB, flat[:, 0], flat[:, 1])
    return np.where(inside, -d, d).reshape(K, nv), edge.reshape(K, nv), along.reshape(K, nv)


class _Sides:
    """A's points measured against B: the projection, the signed value and its derivatives, the step along A."""

    def __init__(self, A: ExactTooth, B: ExactTooth):
        self.A, self.B = A, B

    def project(self, ib, t, Pa):
        """Projection of points ``Pa`` on B's pieces ``ib`` (Newton warm-started at ``t``): parameter and distance."""
        B = self.B
        for _ in range(3):  # warm-started from the last iterate: Newton converges in a few steps
            Qb, b1, b2 = B.eval(ib, t)
            D = Pa - Qb
            t = np.clip(t + (D * b1).sum(-1) / curv_h(b1, -D, b2), B.lo[ib], B.hi[ib])
        Qb = B.eval(ib, t, order=0)[0]
        return t, np.hypot(*(Pa - Qb).T)

    def inner(self, ia, s, ib, t, r_k, sh_k):
        A, B, project = self.A, self.B, self.project
        """A's point at (ia, s); its projection on B's piece ib, or the neighbouring piece when it runs off an end."""
        Pa, a1, a2 = A.eval(ia, s)
        Pa, a1, a2 = rotate(Pa, r_k) + sh_k, rotate(a1, r_k), rotate(a2, r_k)
        t, dist = project(ib, t, Pa)
        for step in (1, -1):  # off the end (start) in travel direction: try the next (previous) piece
            end = np.where(B.sense[ib] * step > 0, B.hi[ib], B.lo[ib])
            nb = ib + step
            off = (t == end) & (nb >= 0) & (nb < B.n)
            if off.any():
                j = np.nonzero(off)[0]
                nbj = nb[j]
                start = np.where(B.sense[nbj] * step > 0, B.lo[nbj], B.hi[nbj])
                tj, dj = project(nbj, start, Pa[j])
                better = dj < dist[j]
                jb = j[better]
                ib = ib.copy()
                ib[jb], t[jb], dist[jb] = nbj[better], tj[better], dj[better]
        Qb, b1, b2 = B.eval(ib, t)
        D = Pa - Qb
        sgn = np.where((D * B.outward(ib, b1)).sum(-1) < 0, -1.0, 1.0)
        far = dist > 1.5 * B.tol  # as in point_signed_distance: the polygon decides away from the curves
        if far.any():
            sgn[far] = np.where(shapely.contains_xy(B.polygon, Pa[far, 0], Pa[far, 1]), -1.0, 1.0)
        g0 = (D * a1).sum(-1)
        h00 = (a1 * a1).sum(-1) + (D * a2).sum(-1)
        h11 = (b1 * b1).sum(-1) - (D * b2).sum(-1)
        h01 = -(a1 * b1).sum(-1)
        interior = (t > B.lo[ib]) & (t < B.hi[ib])
        red = h00 - np.where(interior & (h11 > 0), h01 * h01 / np.where(h11 > 0, h11, 1.0), 0.0)
        red = np.where(dist < _CROSS, np.nan, red)  # at a crossing: see the step below
        fprime = (B.outward(ib, b1) * a1).sum(-1)  # derivative of the signed distance (envelope theorem)
        red = np.where(np.isnan(red), -fprime * 1e300, red)  # marks the rows; read back in the loop
        return ib, t, sgn * dist, g0, red, sgn, (a1 * a1).sum(-1)

    def advance(self, ia, s_old, s_new):
        A = self.A
        """Clamp to the piece; from the piece's end, continue on the next/previous piece of A past the junction."""
        ia = ia.copy()
        hi_end = (s_new > A.hi[ia]) & (s_old >= A.hi[ia])
        lo_end = (s_new < A.lo[ia]) & (s_old <= A.lo[ia])
        fwd = (hi_end & (A.sense[ia] > 0)) | (lo_end & (A.sense[ia] < 0))
        back = (hi_end & (A.sense[ia] < 0)) | (lo_end & (A.sense[ia] > 0))
        over = np.abs(s_new - np.clip(s_new, A.lo[ia], A.hi[ia]))  # parameter left beyond the end
        s_new = np.clip(s_new, A.lo[ia], A.hi[ia])
        for mask, step in ((fwd, 1), (back, -1)):
            nxt = ia + step
            go = mask & (nxt >= 0) & (nxt < A.n)
            if go.any():
                n = nxt[go]
                # carry on along the next piece by the same length (speeds at the junction)
                v_old = np.hypot(*A.eval(ia[go], s_new[go], order=1)[1].T)
                start = np.where(A.sense[n] * step > 0, A.lo[n], A.hi[n])
                v_new = np.maximum(np.hypot(*A.eval(n, start, order=1)[1].T), 1e-300)
                s_go = start + step * A.sense[n] * over[go] * v_old / v_new
                s_new[go] = np.clip(s_go, A.lo[n], A.hi[n])
                ia[go] = n
        return ia, s_new


def _seeds(A: ExactTooth, B: ExactTooth, sd: np.ndarray, rot, shift, margin):
    """Newton's starting rows: ``(pair, A piece, A parameter, B piece, B parameter)`` from the polygon vertices
    whose distance is a local minimum within ``margin`` of the pair's smallest (module docstring)."""
    # seeds: local minima of the vertex sequence within the margin of the pair's minimum (the curve's extrema
    # lie between a vertex and its neighbours; one seed per basin is enough), and the vertices either side:
    # where vertices are sparse (coarse chords, a cycloid's pitch-point cusp) the curve's extremum can lie a
    # chord or two away from the polygon's
    seed_k, seed_v = vertex_seeds(sd, margin, _NEAR)
    # each seed: its vertex's piece (and the neighbouring piece at a junction) against every B piece
    ia = A.vert_piece[seed_v]
    sa = A.vert_t[seed_v]
    rows_k, rows_ia, rows_sa = [seed_k], [ia], [sa]
    at_end = np.isclose(sa, np.where(A.sense[ia] > 0, A.hi[ia], A.lo[ia]), rtol=0, atol=1e-12) & (ia + 1 < A.n)
    if at_end.any():
        nxt = ia[at_end] + 1
        rows_k.append(seed_k[at_end])
        rows_ia.append(nxt)
        rows_sa.append(np.where(A.sense[nxt] > 0, A.lo[nxt], A.hi[nxt]))
    kk = np.concatenate(rows_k)
    ia = np.concatenate(rows_ia)
    s = np.concatenate(rows_sa)
    # the B pieces that can hold the nearest point to the seed (as in point_signed_distance)
    P0 = rotate(A.eval(ia, s, order=0)[0], rot[kk]) + shift[kk]
    d2, g = B.nearest_grid(P0)  # (m, nB) each
    gmin = np.sqrt(d2)
    cand = gmin <= gmin.min(axis=1, keepdims=True) + B.grid_step[None, :]
    row, ib = np.nonzero(cand)
    t = B.grid_t[ib, g[row, ib]]
    kk, ia, s = kk[row], ia[row], s[row]

    return kk, ia, s, ib, t


def _newton(sides: _Sides, ia, s, ib, t, r_k, sh_k, kk):
    """Newton on the signed value of each row (module docstring): the rows' final A pieces and parameters, and
    which rows stopped short of a stationary point or a corner."""
    A = sides.A
    inner, advance = sides.inner, sides.advance
    ib, t, f, g0, red, sgn, a1n = inner(ia, s, ib, t, r_k, sh_k)
    active = np.arange(len(s))
    stuck = np.zeros(len(s), dtype=bool)  # rows that stopped short of a stationary point or a corner
    for _ in range(_NEWTON_STEPS):
        if active.size == 0:
            break
        A_ = active
        # Newton on the signed value f itself (minimised whether apart or overlapping), its derivatives
        # from those of the reduced F(s) = |D|^2/2 = f^2/2: f' = F'/f, f'' = (F'' - f'^2)/f. (Newton on
        # F instead is slow where f is small: F is quartic at a grazing contact, flat at a crossing.)
        gn = np.maximum(a1n[A_], 1e-300)
        fa = f[A_]
        cross = np.abs(red[A_]) > 1e200  # |f| below _CROSS: f' read from the mark, f'' not trusted
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            fp = np.where(cross, -red[A_] / 1e300, g0[A_] / fa)
            fpp = np.where(cross, np.nan, (red[A_] - fp * fp) / fa)
            ds = -fp / fpp
        # where f'' is not positive the minimum is not in this basin of the piece: f falls all the way
        # to the piece's end (or until the curvature turns), so aim for the end (the fractions below
        # catch a turn); from the end, the step carries into the next piece
        wrong = ~(fpp > 0) & ~cross
        if wrong.any():
            rw = A_[wrong]
            end = np.where(fp[wrong] < 0, A.hi[ia[rw]], A.lo[ia[rw]])
            to_end = end - s[rw]
            far_end = np.abs(to_end) > 1e-15 * np.maximum(1.0, np.abs(end))
            ds[wrong] = np.where(far_end, to_end, -np.sign(fp[wrong]) * 1e-2 * np.sqrt(gn[wrong]) / gn[wrong])
        # at a crossing of the curves (f ~ 0): step 0.1 um down the slope (the fractions shorten it)
        if cross.any():
            ds[cross] = -np.sign(fp[cross]) * 1e-4 / np.sqrt(gn[cross])
        ds = np.where(np.isfinite(ds), ds, 0.0)
        moved = np.zeros(len(A_))
        f_before = f[A_].copy()
        # the step and three shorter ones in one call (the cost is per call more than per row); the
        # best of those that do not raise the signed value is taken
        nf = len(_FRACTIONS)
        rows = np.repeat(A_, nf)
        ds_all = (ds[:, None] * _FRACTIONS[None, :]).ravel()
        ia_try, s_try = advance(ia[rows], s[rows], s[rows] + ds_all)
        res = inner(ia_try, s_try, ib[rows], t[rows], r_k[rows], sh_k[rows])
        fv = np.where(res[2] <= f[rows] + 1e-15, res[2], np.inf).reshape(len(A_), nf)
        pick = fv.argmin(axis=1)
        okr = np.isfinite(fv[np.arange(len(A_)), pick])
        sel = (np.arange(len(A_)) * nf + pick)[okr]
        good = A_[okr]
        moved[okr] = np.where(ia_try[sel] == ia[good], np.abs(s_try[sel] - s[good]) * np.sqrt(a1n[good]), np.inf)
        ia[good], s[good] = ia_try[sel], s_try[sel]
        for arr, val in zip((ib, t, f, g0, red, sgn, a1n), res):
            arr[good] = val[sel]
        # at a stationary point the value is second order in the position: 1e-8 mm of position is
        # ~1e-16 mm of clearance on these curvatures (radii > 1e-3 mm)
        # and a row whose full step improved the value by less than _DONE is done whatever its
        # position does (flat, conformal contact): the figure, not the spot, is what is refined; a
        # shortened step is no such evidence, the row goes on
        full = np.zeros(len(A_), dtype=bool)
        full[okr] = pick[okr] == 0
        keep = (moved > 1e-8) & ((f_before - f[A_] > _DONE) | (~full & (f_before - f[A_] > 1e-12)))
        # a row none of whose steps lowered the value although its slope promised more than _DONE from
        # the shortest stopped short: the curvature that sized the steps changed within them (the nearest
        # point of the other tooth reaching a corner: a flank parallel to a flank until it meets the
        # tip's edge). Its figure is an upper bound only, and the caller is told. (A step that left the
        # piece or was clamped at its end met a corner of this tooth instead: the value there was tried.)
        with np.errstate(invalid="ignore"):
            promise = np.abs(fp * ds) * _FRACTIONS[-1]
        last = np.arange(len(A_)) * nf + nf - 1
        inside = (ia_try[last] == ia[A_]) & (s_try[last] != s[A_])
        stuck[A_[~okr & inside & (promise > _DONE)]] = True
        # rows of one pair that have reached the same spot on the same pieces are one row
        key = np.stack([kk[A_], ia[A_], ib[A_], np.round(s[A_] * 1e7)], axis=1)
        _, first = np.unique(key, axis=0, return_index=True)
        dup = np.ones(len(A_), dtype=bool)
        dup[first] = False
        active = A_[keep & ~dup]
    stuck[active] = True  # still descending after _NEWTON_STEPS
    return ia, s, stuck


def _one_side(A: ExactTooth, B: ExactTooth, sd: np.ndarray, rot, shift, margin):
    """``min_s sd_B(P_A(s))`` for each pair (A placed in B's frame by ``rot, shift``), exact; with where it is.

    ``sd`` is :func:`_vertex_sd` of the pairs. Returns value (K,), the A
    piece and parameter, the point (B frame), and whether every row of the
    pair reached a stationary point or a corner.
    """
    K = len(rot)
    kk, ia, s, ib, t = _seeds(A, B, sd, rot, shift, margin)
    r_k, sh_k = rot[kk], shift[kk]
    ia, s, stuck = _newton(_Sides(A, B), ia, s, ib, t, r_k, sh_k, kk)
    # each candidate measured exactly against the whole of B: a true signed distance of a true curve point
    Pa = rotate(A.eval(ia, s, order=0)[0], r_k) + sh_k
    val = point_signed_distance(B, Pa)
    out = np.full(K, np.inf)
    order = np.lexsort((val, kk))
    first = np.ones(len(order), dtype=bool)
    first[1:] = kk[order][1:] != kk[order][:-1]
    pick = order[first]
    out[kk[pick]] = val[pick]
    where_piece = np.full(K, -1)
    where_t = np.full(K, np.nan)
    where_pt = np.full((K, 2), np.nan)
    where_piece[kk[pick]], where_t[kk[pick]], where_pt[kk[pick]] = ia[pick], s[pick], Pa[pick]
    sure = np.ones(K, dtype=bool)
    sure[kk[stuck]] = False
    return out, where_piece, where_t, where_pt, sure


def _rotmat(rot):
    c, s = np.cos(rot), np.sin(rot)
    m = np.empty((len(rot), 2, 2))
    m[:, 0, 0], m[:, 0, 1], m[:, 1, 0], m[:, 1, 1] = c, -s, s, c
    return m


def refine_pairs(
    A: ExactTooth, polyA, geomA, rot_a, shift_a, B: ExactTooth, polyB, geomB, rot_b, shift_b, margin: float, apart=None
):
    """Exact signed clearance ``(K,)`` of pairs of placed teeth (A_k at ``rot_a, shift_a``, B_k at ``rot_b, shift_b``).

    ``polyA``/``polyB`` are the teeth's polygons (own frames), ``geomA``/
    ``geomB`` prepared shapely polygons of them. ``margin`` (mm): vertices
    whose polygon signed distance is within it of the polygon minimum seed
    the refinement (module docstring); at least twice the polygons' distance
    from the curves. ``apart (K,)`` bool, optional: pairs known to be apart
    (their polygon figure above its polygon-curve gap), else found here.

    Returns
    -------
    value : (K,) float, mm
    side : (K,) int
        0 when the extremum is a point of A's boundary (measured against B),
        1 when it is a point of B's.
    point : (K, 2) float
        That point, in B's frame for side 0 and A's frame for side 1.
    """
    (r1, t1), (r2, t2) = _relative(rot_a, shift_a, rot_b, shift_b)
    K = len(r1)
    sd1, edge1, along1 = _vertex_sd(A, polyA, polyB, geomB, r1, t1)
    # the polygons' distance is the smaller vertex distance of the two sides (a polygon's closest point to
    # another is a vertex of one of them); the curves are within margin / 2 of it, so above margin / 2
    # the teeth are apart: their figure is the distance between the curves (wgcad.clearance.apart), and
    # the pairs it leaves unsolved are refined as those that can touch or overlap
    vsd2 = None
    if apart is None:
        vsd2 = _vertex_sd(B, polyB, polyA, geomA, r2, t2)
        apart = np.minimum(sd1.min(axis=1), vsd2[0].min(axis=1)) > 0.5 * margin
    value = np.full(K, np.inf)
    side = np.zeros(K, dtype=int)
    point = np.full((K, 2), np.nan)
    apart = np.nonzero(apart)[0]
    if apart.size:
        v2 = tuple(x[apart] for x in vsd2) if vsd2 is not None else None
        dist, solved, pts, _, sd_apart = _apart_both(
            A, polyA, geomA, B, polyB, (r1[apart], t1[apart]), (r2[apart], t2[apart]), margin,
            (sd1[apart], edge1[apart], along1[apart]), v2,
        )  # fmt: skip
        ok = apart[solved]
        value[ok], point[ok], side[ok] = dist[solved], pts[solved], sd_apart[solved]
    rest = np.nonzero(~np.isfinite(value))[0]
    if rest.size:
        sd2r = vsd2[0][rest] if vsd2 is not None else _vertex_sd(B, polyB, polyA, geomA, r2[rest], t2[rest])[0]
        value[rest], side[rest], point[rest] = _general(
            A, B, sd1[rest], sd2r, r1[rest], t1[rest], r2[rest], t2[rest], margin
        )
    return value, side, point


def _b_side(sd1, sd2, margin):
    """Pairs whose closest approach can be at a vertex of B's polygon: B's vertex distances within ``margin`` of A's.

    The polygons' distance is attained at a vertex of one of them. Where it is B's (B's corner against the middle of
    a long A edge: a root or tip corner of one tooth against the other's flank), A's vertices either side of the
    point can be far more than the margin above the distance, and seeds taken from A's side alone miss that basin
    (0.15 um too high, measured on D4's upper neighbours); from B's side the basin is seeded.
    """
    return sd2.min(axis=1) <= sd1.min(axis=1) + margin


def _apart_both(A, polyA, geomA, B, polyB, pose1, pose2, margin, vsd1, vsd2=None):
    """The batch's distance of pairs apart seeded from A's vertices and, where :func:`_b_side`, from B's too.

    ``pose1``: A's poses in B's frames, ``pose2``: B's in A's; ``vsd1``/``vsd2``: :func:`_vertex_sd` of each side
    (B's computed here when not given). Returns the distance, ``solved`` (every run of the pair solved), the point
    of the side attaining it (A's in B's frame for side 0, B's in A's frame for side 1), the other curve's point in
    the same frame, and the side.
    """
    (r1, t1), (r2, t2) = pose1, pose2
    sd1, edge1, along1 = vsd1
    dist, solved, pts, other = apart_distance(A, B, r1, t1, vertex_seeds(sd1, margin, _NEAR), edge1, along1)
    side = np.zeros(len(r1), dtype=int)
    if vsd2 is None:
        vsd2 = _vertex_sd(B, polyB, polyA, geomA, r2, t2)
    sd2, edge2, along2 = vsd2
    two = np.nonzero(_b_side(sd1, sd2, margin))[0]
    if two.size:
        d2, s2, p2, o2 = apart_distance(
            A=B, B=A, rot=r2[two], shift=t2[two], seeds=vertex_seeds(sd2[two], margin, _NEAR),
            edge=edge2[two], along=along2[two],
        )  # fmt: skip
        solved[two] &= s2
        lower = d2 < dist[two] - 1e-12  # B's side only where it finds more than the distance's rounding
        w = two[lower]
        dist[w], pts[w], other[w], side[w] = d2[lower], p2[lower], o2[lower], 1
    return dist, solved, pts, other, side


def apart_pairs(A: ExactTooth, polyA, rot_a, shift_a, B: ExactTooth, polyB, geomB, rot_b, shift_b, margin: float):
    """Distance between the curves of pairs of placed teeth known to be apart (:mod:`wgcad.clearance.apart`), seeded
    from A's polygon vertices as :func:`refine_pairs` is: ``(distance (K,), solved (K,), A's point, B's point)``, the
    points in B's frame."""
    (r1, t1), (r2, t2) = _relative(rot_a, shift_a, rot_b, shift_b)
    vsd1 = _vertex_sd(A, polyA, polyB, geomB, r1, t1)
    dist, solved, pts, other, side = _apart_both(A, polyA, A.polygon, B, polyB, (r1, t1), (r2, t2), margin, vsd1)
    # B's side measures in A's frame: its points carried to B's frame (A's pose in B's frame, inverted)
    b = np.nonzero(side == 1)[0]
    if b.size:
        pa = rotate(other[b], r1[b]) + t1[b]
        pb = rotate(pts[b], r1[b]) + t1[b]
        pts[b], other[b] = pa, pb
    return dist, solved, pts, other


def _relative(rot_a, shift_a, rot_b, shift_b):
    """A's poses in B's frames and B's in A's, ``((rot, shift), (rot, shift))``, B's poses broadcast to A's count."""
    rot_a = np.atleast_1d(np.asarray(rot_a, dtype=float))
    K = len(rot_a)
    rot_b = np.broadcast_to(np.asarray(rot_b, dtype=float), (K,))
    shift_a = np.atleast_2d(np.asarray(shift_a, dtype=float))
    shift_b = np.broadcast_to(np.asarray(shift_b, dtype=float), (K, 2))
    return relative_pose(rot_a, shift_a, rot_b, shift_b), relative_pose(rot_b, shift_b, rot_a, shift_a)


def _general(A: ExactTooth, B: ExactTooth, sd1, sd2, r1, t1, r2, t2, margin):
    """Both sides' refinement of pairs that can touch or overlap (or whose distance the batch left unsolved)."""
    K = len(r1)
    v1, _, _, p1, sure = _one_side(A, B, sd1, r1, t1, margin)
    # for teeth apart both sides' minima are the one distance between their boundaries: the second side is
    # measured only for pairs that can touch or overlap, for pairs whose first side has a row that stopped
    # short of a stationary point (its figure only bounds), and where the closest approach can be at one of B's
    # vertices, whose basin A's seeds can miss (_b_side)
    v2 = np.full(K, np.inf)
    p2 = np.full((K, 2), np.nan)
    touch = np.minimum(sd1.min(axis=1), sd2.min(axis=1)) <= 0.5 * margin
    two = np.nonzero(touch | ~sure | _b_side(sd1, sd2, margin))[0]
    if two.size:
        v2[two], _, _, p2[two], _ = _one_side(B, A, sd2[two], r2[two], t2[two], margin)
    side = (v2 < v1).astype(int)
    return np.minimum(v1, v2), side, np.where(side[:, None] == 0, p1, p2)
