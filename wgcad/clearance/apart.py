"""Exact distance of placed teeth that are apart, many pairs in one batch (docs/models.md 5).

The general refinement (:mod:`wgcad.clearance.refine`) finds the signed
clearance of any two placed teeth, overlapping or not; its cost is per
call and per Newton step more than per pair. Most pairs an audit refines
are apart (their polygons are farther apart than the polygon-curve gap),
and for those the figure is the distance between the two curves,
``min |P_A(s) - P_B(t)|``. This module finds it by one joint Newton
iteration on ``(s, t)`` for all pairs at once, seeded as the general
refinement is:

- Seeds: A's period vertices whose polygon distance to B is a local
  minimum within the margin of the pair's smallest (and their
  neighbours), each on its piece; the B point to start from is the nearest
  point of B's polygon, on the piece of its edge.
- Newton on ``F = |P_A(s) - P_B(t)|^2 / 2`` with its exact gradient and
  Hessian (where F is not convex, a gradient step scaled by the curves'
  speeds). A step that would leave a piece stops at its end; pushed on
  from there, the row carries on along the next piece (pieces meet end to
  end along the outline); at the ends of the period the parameter is held
  and Newton goes on in the other one. A step that raised ``F`` is taken
  back and halved.

Every row's figure is the distance between two true curve points, so the
smallest is an upper bound of the exact distance, and it is the exact
distance once a seed lies in the basin of the true minimum - the premise
of the general refinement too, from the same vertices. The caller seeds
from both teeth's vertices where the closest approach can be a corner of
the other tooth (:func:`wgcad.clearance.refine.refine_pairs`). A pair is solved
only if every one of its rows converged (its last step moved the points by
less than 1e-7 mm at a point where F is convex along the free parameters),
ended within two vertices of its seed along A's outline (a joint descent
can slide into a basin its seed does not stand for) and at B's nearest
point to it; the others are left to the general refinement. tests/test_apart.py checks
the figures against it to 1e-9 mm on every template.
"""

from __future__ import annotations

import numpy as np

from ..plane import rotate
from .exact import ExactTooth, point_signed_distance

__all__ = ["apart_distance", "vertex_seeds"]

#: Newton steps at most; a row still moving then is left to the general refinement
_STEPS = 12
#: a row whose Newton step moves its points less than this (mm) has converged: the step is quadratically convergent
#: (the next would move them ~1e-14 mm) and the distance at a minimum is second order in the position
_MOVED = 1e-7
#: a parameter whose own Newton step moves its point less than this (mm) is settled: the other may change piece
_SETTLED = 1e-7
#: piece changes a row may make; a row that keeps crossing a junction sits at a corner there and is held
_SWITCHES = 8


def vertex_seeds(sd: np.ndarray, margin: float, near=(1,)) -> tuple[np.ndarray, np.ndarray]:
    """The seed vertices ``(pair, vertex)`` of vertex distances ``sd (K, nv)``: local minima of the sequence within
    ``margin`` of the pair's smallest, with their ``near`` neighbours (as :func:`wgcad.clearance.refine._seeds`)."""
    lo = sd.min(axis=1)
    pad = np.pad(sd, ((0, 0), (1, 1)), constant_values=np.inf)
    local = (sd <= pad[:, :-2]) & (sd <= pad[:, 2:])
    around = local.copy()
    for sh in near:
        around[:, sh:] |= local[:, :-sh]
        around[:, :-sh] |= local[:, sh:]
    return np.nonzero(around & (sd <= lo[:, None] + margin))


def apart_distance(A: ExactTooth, B: ExactTooth, rot, shift, seeds, edge, along):
    """Distance ``(K,)`` between the curves of A (placed in B's frame by ``rot (K,)``, ``shift (K, 2)``) and B.

    ``seeds``: ``(pair, vertex)`` of :func:`vertex_seeds`; ``edge``,
    ``along`` ``(K, nv)``: the nearest edge of B's polygon to each of A's
    period vertices and the position on it (:func:`wgcad.clearance.distance.outline_distance`).
    The pairs must be apart. Returns the distances, ``solved (K,)``:
    False where a row did not converge or a seed's nearest edge is not on
    B's pieces (the body's closing edges): the figure is then not to be used;
    and the points of A's and of B's curve where the distance is attained, in B's frame.
    """
    K = len(rot)
    kk, v = seeds
    ia, s = A.vert_piece[v].copy(), A.vert_t[v].copy()
    # the B point to start from: the nearest point of B's polygon, on the piece of its edge
    e = edge[kk, v]
    u = along[kk, v]
    pos = e - B.vert_index[0]
    on = (pos >= 0) & (pos + 1 < B.n_vert)
    pos = np.clip(pos, 0, B.n_vert - 2)
    p0, p1 = B.vert_piece[pos], B.vert_piece[pos + 1]
    t0, t1 = B.vert_t[pos], B.vert_t[pos + 1]
    ib = np.where((p0 == p1) | (u < 0.5), p0, p1)
    t = np.where(p0 == p1, t0 + u * (t1 - t0), np.where(u < 0.5, t0, t1))
    # an edge across a junction has one end on each piece: from that vertex, the seed's projection on the piece
    # (an edge's far end can lie where F is not convex, and the descent from there crawls)
    cross = np.nonzero(p0 != p1)[0]
    if cross.size:
        # projected on both pieces, the nearer taken (on the wrong one the projection is its end, and the
        # joint descent from there can slide A into another basin)
        Pa = rotate(A.eval(ia[cross], s[cross], order=0)[0], rot[kk[cross]]) + shift[kk[cross]]
        m = cross.size
        both = np.concatenate([p0[cross], p1[cross]])
        tb = B._project(np.concatenate([Pa, Pa]), both, np.concatenate([t0[cross], t1[cross]]), steps=8)
        gap = np.hypot(*(np.concatenate([Pa, Pa]) - B.eval(both, tb, order=0)[0]).T)
        second = gap[m:] < gap[:m]
        ib[cross] = np.where(second, p1[cross], p0[cross])
        t[cross] = np.where(second, tb[m:], tb[:m])
    dist, done = _newton(A, B, rot[kk], shift[kk], ia, s, ib, t)
    ok = done & on
    done[ok] = _kept(A, B, kk[ok], v[ok], ia[ok], s[ok], rot[kk[ok]], shift[kk[ok]], dist[ok])
    done &= ok
    out = np.full(K, np.inf)
    point = np.full((K, 2), np.nan)
    order = np.lexsort((dist, kk))
    first = np.ones(len(order), dtype=bool)
    first[1:] = kk[order][1:] != kk[order][:-1]
    pick = order[first]
    out[kk[pick]] = dist[pick]
    point[kk[pick]] = rotate(A.eval(ia[pick], s[pick], order=0)[0], rot[kk[pick]]) + shift[kk[pick]]
    other = np.full((K, 2), np.nan)
    other[kk[pick]] = B.eval(ib[pick], t[pick], order=0)[0]
    solved = np.zeros(K, dtype=bool)
    solved[kk] = True
    solved[kk[~done]] = False
    return out, solved & np.isfinite(out), point, other


def _kept(A: ExactTooth, B: ExactTooth, kk, v, ia, s, rot, shift, dist) -> np.ndarray:
    """Rows whose end is the minimum their seed stands for: within two vertices of the seed along A's outline (a
    joint descent can slide along a valley into another basin, which the seed does not stand for: its own
    may be lower), at B's nearest point to it (:func:`wgcad.clearance.exact.point_signed_distance`)."""
    vpos = _outline_pos(A, A.vert_piece, A.vert_t)
    last = A.n_vert - 1
    pos = _outline_pos(A, ia, s)
    within = (pos >= vpos[np.maximum(v - 2, 0)] - 1e-12) & (pos <= vpos[np.minimum(v + 2, last)] + 1e-12)
    nearest = np.zeros(len(v), dtype=bool)
    w = np.nonzero(within & np.isfinite(dist))[0]
    if w.size:
        pts = rotate(A.eval(ia[w], s[w], order=0)[0], rot[w]) + shift[w]
        # rows of one pair that ended on one point (a seed's neighbours reach its minimum too) are measured once
        key = np.column_stack([kk[w], np.round(pts * 1e9)])
        _, first, back = np.unique(key, axis=0, return_index=True, return_inverse=True)
        ok = point_signed_distance(B, pts[first]) >= dist[w][first] - 1e-11
        nearest[w] = ok[back.ravel()]
    return nearest


def _outline_pos(T: ExactTooth, idx, par) -> np.ndarray:
    """Position along the outline: piece index plus the fraction of the piece travelled."""
    frac = (par - T.lo[idx]) / np.maximum(T.hi[idx] - T.lo[idx], 1e-300)
    return idx + np.where(T.sense[idx] > 0, frac, 1.0 - frac)


def _end(T: ExactTooth, idx, par):
    """+1 (-1) where ``par`` is at the upper (lower) end of piece ``idx`` to rounding, else 0."""
    eps = 1e-13 * (1.0 + np.abs(T.hi[idx] - T.lo[idx]))
    return np.where(par >= T.hi[idx] - eps, 1, np.where(par <= T.lo[idx] + eps, -1, 0))


def _segment(T: ExactTooth, idx, par, step):
    """Parameter range of the piece (of a spline: of its cubic segment ``[k, k + 1]``) a row at ``par`` steps in."""
    lo, hi = T.lo[idx], T.hi[idx]
    spline = getattr(T, "_spline", None)
    if spline is None:
        spline = T._spline = np.array([p.kind == "spline" for p in T.pieces])
    sp = spline[idx]
    if sp.any():
        k = np.floor(par)
        k = np.where((par == k) & (step < 0), k - 1.0, k)  # on a joint stepping down: the segment below
        # a step across several segments is taken (far from the minimum the model's error does not matter,
        # and segments can be microns long); one that would end in the next segment stops at the joint
        sp &= np.abs(np.floor(par + step) - k) < 2.0
        lo = np.where(sp, np.maximum(lo, k), lo)
        hi = np.where(sp, np.minimum(hi, k + 1.0), hi)
    return lo, hi


def _neighbour(T: ExactTooth, idx, forward_param: np.ndarray):
    """The piece a row enters leaving piece ``idx`` in the direction of increasing (``forward_param``) or
    decreasing parameter, and the parameter there; -1 past the ends of the period."""
    along_travel = np.where(forward_param, T.sense[idx] > 0, T.sense[idx] < 0)
    nxt = np.where(along_travel, idx + 1, idx - 1)
    ok = (nxt >= 0) & (nxt < T.n)
    n = np.clip(nxt, 0, T.n - 1)
    # entering the next piece at its travel start, the previous one at its travel end
    start = np.where(T.sense[n] > 0, T.lo[n], T.hi[n])
    end = np.where(T.sense[n] > 0, T.hi[n], T.lo[n])
    return np.where(ok, n, -1), np.where(along_travel, start, end)


def _newton(A, B, rot, shift, ia, s, ib, t):
    """Joint Newton on ``|P_A(s) - P_B(t)|^2 / 2`` (module docstring): distance and whether each row converged."""
    rows = _Rows(A, B, rot, shift, ia, s, ib, t)
    live = np.arange(len(s))
    for _ in range(_STEPS):
        if live.size == 0:
            break
        live = rows.step(live)
    return rows.dist, rows.done


class _Rows:
    """The rows' state: pieces and parameters, the last accepted step (to halve), the piece each came from."""

    def __init__(self, A, B, rot, shift, ia, s, ib, t):
        M = len(s)
        self.A, self.B, self.rot, self.shift = A, B, rot, shift
        self.ia, self.s, self.ib, self.t = ia, s, ib, t
        self.F_old = np.full(M, np.inf)
        self.s_old, self.t_old, self.ia_old, self.ib_old = s.copy(), t.copy(), ia.copy(), ib.copy()
        self.ds = np.zeros(M)
        self.dt = np.zeros(M)
        self.switches = np.zeros(M, dtype=int)
        self.came_a = np.full(M, -1)
        self.came_b = np.full(M, -1)
        self.done = np.zeros(M, dtype=bool)
        self.dist = np.full(M, np.inf)

    def step(self, live):
        """One Newton step of rows ``live``; the rows still to go on."""
        A, B = self.A, self.B
        Pa, a1, a2 = A.eval(self.ia[live], self.s[live])
        r_L = self.rot[live]
        Pa = rotate(Pa, r_L) + self.shift[live]
        a1, a2 = rotate(a1, r_L), rotate(a2, r_L)
        Qb, b1, b2 = B.eval(self.ib[live], self.t[live])
        r = Pa - Qb
        F = 0.5 * (r * r).sum(-1)
        va, vb = np.hypot(*a1.T), np.hypot(*b1.T)
        up, retry = self._retreat(live, F, va, vb)
        ok = ~up
        L = live[ok]
        r, a1, a2, b1, b2, F, va, vb = r[ok], a1[ok], a2[ok], b1[ok], b2[ok], F[ok], va[ok], vb[ok]
        self.dist[L] = np.sqrt(2.0 * F)
        g = ((r * a1).sum(-1), -(r * b1).sum(-1))
        h = (va * va + (r * a2).sum(-1), vb * vb - (r * b2).sum(-1), -(a1 * b1).sum(-1))
        ns, nt, convex, go_s, go_t, ends = self._plan(L, g, h, va, vb)
        s_L, t_L = self.s[L], self.t[L]
        # a step that would leave a piece is shortened to end on its end, both parameters alike (clamping each
        # alone would turn a slide along two nearly parallel flanks into a jump off them); on a spline, on the
        # end of its cubic segment (the second derivative jumps at the joints: Newton's model holds within one)
        loA, hiA = _segment(A, self.ia[L], s_L, ns)
        loB, hiB = _segment(B, self.ib[L], t_L, nt)
        with np.errstate(divide="ignore", invalid="ignore"):
            room_s = np.where(ns > 0, (hiA - s_L) / ns, np.where(ns < 0, (loA - s_L) / ns, np.inf))
            room_t = np.where(nt > 0, (hiB - t_L) / nt, np.where(nt < 0, (loB - t_L) / nt, np.inf))
        frac = np.clip(np.minimum(room_s, room_t), 0.0, 1.0)
        s_new = np.clip(s_L + frac * ns, loA, hiA)
        t_new = np.clip(t_L + frac * nt, loB, hiB)
        # converged: the whole step (not what is left of it at a piece's end: a row a rounding error short of
        # the end has no room left, yet has not converged) below _MOVED where F is convex along the free parameters
        conv = (np.hypot(ns * va, nt * vb) < _MOVED) & convex & ~go_s & ~go_t
        self.done[L[conv]] = True
        keep = ~conv
        G = L[keep]
        self.s_old[G], self.t_old[G], self.F_old[G] = s_L[keep], t_L[keep], F[keep]
        self.ia_old[G], self.ib_old[G] = self.ia[G], self.ib[G]
        self.ds[G], self.dt[G] = (s_new - s_L)[keep], (t_new - t_L)[keep]
        self.s[G], self.t[G] = s_new[keep], t_new[keep]
        self._switch(L, keep, go_s, go_t, ends, s_new - s_L, t_new - t_L)
        return np.concatenate([G, retry])

    def _retreat(self, live, F, va, vb):
        """Rows whose last step raised F (by more than 1e-12 mm of distance: the same point on the next piece's
        formula differs by rounding) take it back halved, on the pieces it started from; halved to nothing, a
        row is left unconverged. Which rows, and those to try again."""
        A, B = self.A, self.B
        Fo = self.F_old[live]
        up = F > Fo + 1e-12 * np.sqrt(2.0 * np.where(np.isfinite(Fo), Fo, 0.0)) + 1e-30
        u = live[up]
        self.ds[u] *= 0.5
        self.dt[u] *= 0.5
        self.ia[u], self.ib[u] = self.ia_old[u], self.ib_old[u]
        self.s[u] = np.clip(self.s_old[u] + self.ds[u], A.lo[self.ia[u]], A.hi[self.ia[u]])
        self.t[u] = np.clip(self.t_old[u] + self.dt[u], B.lo[self.ib[u]], B.hi[self.ib[u]])
        return up, u[np.hypot(self.ds[u] * va[up], self.dt[u] * vb[up]) >= 1e-13]

    def _plan(self, L, g, h, va, vb):
        """The step of rows ``L`` at the ends of their pieces: at an end where F falls out of the piece (its
        gradient) the row carries on along the next piece, or holds the parameter (the period's end, or a
        corner) and steps in the other one alone. Returns the step, whether F is convex along the free
        parameters, which rows change piece, and the pieces they go to."""
        A, B = self.A, self.B
        g0, g1 = g
        h00, h11, h01 = h
        ns, nt, newton = _step(g0, g1, h00, h11, h01, va, vb)
        ia_L, ib_L = self.ia[L], self.ib[L]
        end_s = _end(A, ia_L, self.s[L])
        end_t = _end(B, ib_L, self.t[L])
        out_s = end_s * g0 < 0
        out_t = end_t * g1 < 0
        # at an end where F falls into the piece but the joint step points out of it: a scaled gradient step
        wrong = ((end_s * ns > 0) & ~out_s) | ((end_t * nt > 0) & ~out_t)
        ns = np.where(wrong, -g0 / np.maximum(va * va, 1e-300), ns)
        nt = np.where(wrong, -g1 / np.maximum(vb * vb, 1e-300), nt)
        newton = newton & ~wrong
        n_s, e_s = _neighbour(A, ia_L, end_s > 0)
        n_t, e_t = _neighbour(B, ib_L, end_t > 0)
        # a piece is left only once the other parameter sits at its nearest point (F's slope along one curve
        # is the distance's only where the other is settled; before, it can point off a piece the reduced
        # distance falls into); a parameter that itself wants off its piece cannot settle: the other may go
        # first. A row sent straight back to the piece it has just left sits at a corner there: it holds it
        with np.errstate(divide="ignore", invalid="ignore"):
            t_alone = np.where(h11 > 0, -g1 / h11, -g1 / np.maximum(vb * vb, 1e-300))
            s_alone = np.where(h00 > 0, -g0 / h00, -g0 / np.maximum(va * va, 1e-300))
        sw = self.switches[L] < _SWITCHES
        go_s = out_s & (n_s >= 0) & sw & ((np.abs(t_alone) * vb < _SETTLED) | out_t) & (n_s != self.came_a[L])
        go_t = out_t & (n_t >= 0) & sw & ((np.abs(s_alone) * va < _SETTLED) | out_s) & (n_t != self.came_b[L])
        go_t &= ~go_s  # one at a time: the step is recomputed on the new piece
        hold_s = out_s & ~go_s
        hold_t = out_t & ~go_t & ~go_s
        # one parameter held: Newton (or a scaled gradient step) in the other; a row that changes piece only
        # changes piece this step (the other parameter's step assumed this one moves)
        nt = np.where(hold_s & ~hold_t, t_alone, nt)
        ns = np.where(hold_t & ~hold_s, s_alone, ns)
        switch = go_s | go_t
        ns = np.where(hold_s | switch, 0.0, ns)
        nt = np.where(hold_t | switch, 0.0, nt)
        convex = np.where(hold_s & hold_t, True, np.where(hold_s, h11 > 0, np.where(hold_t, h00 > 0, newton)))
        return ns, nt, convex, go_s, go_t, (n_s, e_s, n_t, e_t)

    def _switch(self, L, keep, go_s, go_t, ends, moved_s, moved_t):
        """The piece changes (at the junction the point is the same, so is F); a row that moves forgets the piece
        it came from."""
        n_s, e_s, n_t, e_t = ends
        for mask, idx, par, nxt, ent, came, moved in (
            (go_s, self.ia, self.s, n_s, e_s, self.came_a, moved_s),
            (go_t, self.ib, self.t, n_t, e_t, self.came_b, moved_t),
        ):
            came[L[moved != 0]] = -1
            m = mask & keep
            came[L[m]] = idx[L[m]]
            idx[L[m]] = nxt[m]
            par[L[m]] = ent[m]
        self.switches[L[(go_s | go_t) & keep]] += 1


def _step(g0, g1, h00, h11, h01, va, vb):
    """The step in ``(s, t)``: Newton's where the Hessian of F is positive definite; where it is indefinite (two
    flanks whose distance has no minimum inside their pieces), down the direction of negative curvature as far as
    the pieces go (the caller shortens it to their ends); else a gradient step scaled by the speeds. And whether it
    was Newton's."""
    det = h00 * h11 - h01 * h01
    pd = (h00 > 0) & (det > 1e-12 * np.abs(h00 * h11))
    with np.errstate(divide="ignore", invalid="ignore"):
        ns = np.where(pd, -(h11 * g0 - h01 * g1) / det, -g0 / np.maximum(va * va, 1e-300))
        nt = np.where(pd, -(h00 * g1 - h01 * g0) / det, -g1 / np.maximum(vb * vb, 1e-300))
        neg = ~pd & (det < 0)
        if neg.any():
            lam = 0.5 * (h00 + h11) - np.sqrt(0.25 * (h00 - h11) ** 2 + h01 * h01)  # the negative eigenvalue
            # its eigenvector, from whichever row of (H - lam I) is better conditioned
            use0 = np.abs(h00 - lam) >= np.abs(h11 - lam)
            es = np.where(use0, -h01, h11 - lam)
            et = np.where(use0, h00 - lam, -h01)
            # downhill, and long: 1 mm of travel along the curves at the current speeds
            sgn = np.where(g0 * es + g1 * et > 0, -1.0, 1.0)
            norm = np.maximum(np.hypot(es * va, et * vb), 1e-300)
            ns = np.where(neg, sgn * es / norm, ns)
            nt = np.where(neg, sgn * et / norm, nt)
    return ns, nt, pd
