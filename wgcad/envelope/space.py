"""The rigid tooth space conjugate to a flexspline tooth: the branch of the envelope that bounds the region the tooth sweeps (docs/models.md 13).

In the rigid gear's frame tooth 0 of the flexspline sweeps a region as the
generator turns it through the mesh. A rigid tooth made for it must stay
outside that region and touch its boundary: the conjugate flank is the part
of the envelope (:func:`wgcad.envelope.envelope`) on the region's boundary.
The branch is chosen that way, explicitly: an envelope point is kept when the
tooth, just before and just after it touches the point, lies on its inner
side (exact: the distance from the point to the placed flank, by Newton's
projection), and when no other position of the pass covers it (the tooth's
chord polygon, to the drive's tolerance). Kept points are exact (Newton
residual below 1e-9 mm); between them the flank is drawn by chords, whose
sagitta is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from wgcad.plane import rotate

from .conjugate import STEP_TOL, envelope, flank_pieces
from .motion import LawMotion

__all__ = ["ConjugateFlank", "conjugate_flank"]


@dataclass(frozen=True, slots=True)
class ConjugateFlank:
    """One flank of the rigid tooth space conjugate to the flexspline tooth (rigid frame, mm, rad).

    Attributes
    ----------
    points : (M, 2) float
        Exact envelope points on the boundary of the swept region, ordered by radius.
    t : (M,) float
        Generator angle at which each is touched.
    normal : (M, 2) float
        The flank's unit normal at each (the envelope's normal there).
    residual_mm : (M,) float
        Their Newton residuals.
    sagitta_mm : float
        The largest gap between the chords joining them and the exact envelope (measured at the chords' middles).
    motion : LawMotion
    """

    points: np.ndarray
    t: np.ndarray
    residual_mm: np.ndarray
    sagitta_mm: float
    motion: object
    normal: np.ndarray = None


def _outside_all(x: np.ndarray, polys: np.ndarray, tol: float, exact) -> np.ndarray:
    """For points ``x (M, 2)``: whether no position of the tooth covers one. The chord polygons ``polys (K, N, 2)``
    decide where they cover a point by more than ``tol`` (their distance from the exact pieces); closer calls go to
    ``exact(I, J)``, the points' ``I`` exact signed distances from the tooth at positions ``J`` (positive: inside),
    all in one call. The points are the tree and each polygon asks it once (a polygon asking is prepared once; the
    points asking a tree of polygons met an unprepared polygon at every pair)."""
    geoms = shapely.polygons(polys)
    pts = shapely.points(x)
    ok = np.ones(len(x), dtype=bool)
    hj, hi = shapely.STRtree(pts).query(geoms, predicate="intersects")
    if not hi.size:
        return ok
    order = np.lexsort((hj, hi))  # by point, then position: the same pairs whatever the tree's order
    hi, hj = hi[order], hj[order]
    depth = shapely.distance(pts[hi], shapely.get_exterior_ring(geoms)[hj])
    # covered, or within the chord tolerance of being covered by a sampled position: between the pass's
    # positions (2e-3 rad apart) a tooth corner sweeps farther than the exact test at the samples sees (held
    # to the strict test, the cycloidal flank kept points below the tip's path, crossed by 0.17 um)
    ok[hi[depth > tol]] = False
    ask = np.flatnonzero((depth <= tol) & ok[hi])
    if ask.size:
        # one covering position is enough: each point's deepest pair first, then the others of the points it left
        ask = ask[np.lexsort((-depth[ask], hi[ask]))]
        lead = np.concatenate([[True], hi[ask][1:] != hi[ask][:-1]])
        for part in (ask[lead], ask[~lead]):
            part = part[ok[hi[part]]]
            if part.size:
                ok[hi[part[exact(hi[part], hj[part]) > -tol]]] = False
    return ok


def _side_distance(piece, s0, x, rot, shift, with_gap: bool = False):
    """Signed distance of points ``x (M, 2)`` from ``piece`` placed at ``(rot, shift)`` (arrays), positive on the
    tooth's side, by Newton's projection started at ``s0``.

    A tooth's pieces run from its centre line toward the space with the material on their left; the parameter
    may run either way (an involute's roll parameter falls toward the root, an arc's angle may rise), so the
    side is taken from the direction of travel, ``t0 -> t1``, not from ``p'`` alone (a double-arc flank, whose
    angles rise, read every point on the wrong side). A point is done once its step along the piece is below
    :data:`~wgcad.envelope.conjugate.STEP_TOL` (1e-13 mm: the rounding of coordinates near 80 mm moves the
    iterates by ~1e-14 mm for ever, and the distance's error is of second order in the step); at most 30 steps."""
    s = np.array(s0, dtype=float)
    lo, hi = min(piece.t0, piece.t1), max(piece.t0, piece.t1)
    live = np.arange(len(s))
    for _ in range(30):
        r, sl = rot[live], s[live]
        X = rotate(piece.point(sl), r) + shift[live]
        d1, d2 = rotate(piece.deriv(sl), r), rotate(piece.deriv2(sl), r)
        e = X - x[live]
        f = np.einsum("ij,ij->i", e, d1)
        df = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", e, d2)
        s_new = np.clip(sl - f / df, lo, hi)
        moved = np.abs(s_new - sl) * np.hypot(d1[:, 0], d1[:, 1]) >= STEP_TOL
        s[live] = s_new
        live = live[moved]
        if not live.size:
            break
    X = rotate(piece.point(s), rot) + shift
    d1 = rotate(piece.deriv(s), rot)
    travel = 1.0 if piece.t1 >= piece.t0 else -1.0
    n = -travel * np.stack([d1[:, 1], -d1[:, 0]], axis=-1) / np.linalg.norm(d1, axis=-1)[:, None]  # left of travel
    side = np.einsum("ij,ij->i", x - X, n)
    return (side, np.hypot(*(x - X).T)) if with_gap else side


def _exact_side(x: np.ndarray, rot: np.ndarray, shift: np.ndarray, outline, starts) -> np.ndarray:
    """The signed distance of each point ``x (M, 2)`` from the tooth (its pieces ``outline``) placed at ``(rot,
    shift)`` (one pose a point), positive inside: the side of the nearest point of the tooth (by distance: a
    projection clamped to a piece's end measures along that end's normal, which can point either way for a point
    off the piece). Each piece's projection starts at the nearest of its ``starts``; a piece is projected on only
    where it can hold the nearest point: its nearest start no farther than the nearest start of all plus the
    longest step between its own starts (a point of the piece lies within half a step of a start), and again,
    against the nearest projection found, where a projection lands farther than its start."""
    c, sn = np.cos(rot)[:, None], np.sin(rot)[:, None]
    s0, near, step = [], [], []
    for p, sg in zip(outline, starts):
        P = p.point(sg)
        px = P[None, :, 0] * c - P[None, :, 1] * sn + shift[:, None, 0]
        py = P[None, :, 0] * sn + P[None, :, 1] * c + shift[:, None, 1]
        dist = np.hypot(px - x[:, None, 0], py - x[:, None, 1])
        k = np.argmin(dist, axis=1)
        s0.append(sg[k])
        near.append(dist[np.arange(len(x)), k])
        step.append(float(np.hypot(*np.diff(P, axis=0).T).max()))
    near = np.array(near)  # (pieces, M)
    best, gap = np.full(len(x), np.inf), np.full(len(x), np.inf)
    done = np.zeros(near.shape, dtype=bool)
    bound = near.min(axis=0)  # the nearest start of all: the nearest point is no farther
    while True:
        # in the pieces' order, as one pass over them all would take them (ties: the first piece's side)
        todo = ~done & (near <= bound[None, :] + np.array(step)[:, None])
        if not todo.any():
            return best
        for j in np.flatnonzero(todo.any(axis=1)):
            i = np.flatnonzero(todo[j])
            d, g = _side_distance(outline[j], s0[j][i], x[i], rot[i], shift[i], with_gap=True)
            closer = g < gap[i]
            best[i[closer]], gap[i[closer]] = d[closer], g[closer]
        done |= todo
        bound = gap  # a piece left out whose start step reaches below the nearest projection found is taken next


def _locally_outside(env, idx, pieces, mot, h: float = 2e-4) -> np.ndarray:
    """Whether the tooth, a little before and after it touches each point, lies on its inner side: the envelope
    branch that bounds the swept region (the other branches are crossed by the tooth's neighbouring positions)."""
    ok = np.zeros(len(idx), dtype=bool)
    for k in np.unique(env.piece[idx]):
        sel = idx[env.piece[idx] == k]
        x = env.points[sel]
        both = []
        for dt in (-h, h):
            rot, shift = mot.pose(env.t[sel] + dt)
            both.append(_side_distance(pieces[k], env.s[sel], x, rot, shift))
        # the pieces run with the tooth's material on the left of their direction, so the tooth lies on the side
        # of -(p'_y, -p'_x): at a boundary point both neighbouring positions are on that side (distance <= 0)
        ok[np.isin(idx, sel)] = (both[0] <= 1e-12) & (both[1] <= 1e-12)
    return ok


def _boundary(env, idx, t, polys, tol, pieces, mot, outline):
    """The envelope points ``idx`` on the boundary of the region the tooth sweeps: locally outside (the flank
    ``pieces``), and covered by no position of the whole tooth (its pitch's pieces ``outline``: a point near the tip
    is covered by the tip, which one flank's pieces do not see; with them alone the cycloidal flank kept points
    below the tip's path and the tooth crossed it by 0.17 um)."""
    idx = idx[_locally_outside(env, idx, pieces, mot)]
    x = env.points[idx]
    starts = [np.linspace(p.t0, p.t1, 64) for p in outline]

    def exact(I, J):
        # every pair at once, in chunks that keep the start grid's arrays small
        out = np.empty(len(I))
        for a in range(0, len(I), 4096):
            i, j = I[a : a + 4096], J[a : a + 4096]
            rot, shift = mot.pose(t[j])
            out[a : a + 4096] = _exact_side(x[i], rot, shift, outline, starts)
        return out

    keep = idx[_outside_all(x, polys, tol, exact)]
    return keep[np.argsort(np.hypot(*env.points[keep].T))]


def conjugate_flank(
    drive,
    z: float | None = None,
    side: int = 1,
    t_max: float = 1.4,
    steps: int = 1401,
    points: int = 50,
    sagitta_tol: float = 5e-6,
) -> ConjugateFlank:
    """The rigid flank conjugate to the flexspline tooth of ``drive`` under its law at section ``z`` (default:
    the generator's centre section), on the ``side`` (+1: y > 0) of tooth 0's path.

    The pass (generator angle ``-t_max .. t_max`` in ``steps`` positions) finds where the flank is touched; the
    envelope is then taken again at ``points`` angles over that stretch, doubled until the chords between its points
    lie within ``sagitta_tol`` (mm) of the envelope. A point is on the boundary when no
    position of the tooth's chord polygon (the drive's tolerance) covers it by more than that tolerance.
    """
    law = drive.law_at(z) if z is not None else drive.law
    d = drive.design.drive
    mot = LawMotion(law, drive.r_m, d.z_flex, d.z_rigid)
    pieces = flank_pieces(drive.flex, side)
    poly = drive.flex.tooth_polygon()
    tol = drive.tol
    t = np.linspace(-t_max, t_max, steps)
    rot, shift = mot.pose(t)
    c, s = np.cos(rot), np.sin(rot)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], 1)
    polys = np.einsum("kij,nj->kni", R, poly) + shift[:, None]

    def rigid_side(env):
        r = np.hypot(*env.points.T)
        near = r > drive.rigid.r_a - 1e-9 if drive.rigid.spec.internal else r < drive.rigid.r_a + 1e-9
        return np.flatnonzero(near)

    env = envelope(pieces, mot, t)
    keep = _boundary(env, rigid_side(env), t, polys, tol, pieces, mot, drive.flex.pieces)
    if len(keep) < 2:
        raise ValueError("the flexspline tooth never touches the rigid tooth's side of its path: no conjugate flank")
    # again, finely, over the stretch of the pass where the flank is touched, until the chords lie within
    # sagitta_tol of the envelope (doubling the angles up to 64 times the first count)
    dt = t[1] - t[0]
    lo, hi = env.t[keep].min() - 3 * dt, env.t[keep].max() + 3 * dt
    n = points
    while True:
        env = envelope(pieces, mot, np.linspace(lo, hi, n))
        keep = _boundary(env, rigid_side(env), t, polys, tol, pieces, mot, drive.flex.pieces)
        sag = _sagitta(env, keep, pieces, mot)
        if sag < sagitta_tol or n >= 64 * points:
            break
        n *= 2
    # the flank's ends to a 64th of that step: where the boundary starts and stops does not hang on the grid
    # (D1 involute at 50 angles: its first point 20 um above the tip circle; the rigid tip follows it)
    step = (hi - lo) / (n - 1)
    tk = env.t[keep]
    extra = [np.linspace(tk.min() - step, tk.min(), 65), np.linspace(tk.max(), tk.max() + step, 65)]
    ends = envelope(pieces, mot, np.concatenate(extra))
    ek = _boundary(ends, rigid_side(ends), t, polys, tol, pieces, mot, drive.flex.pieces)
    if len(ek):
        merged = {
            f: np.concatenate([getattr(env, f)[keep], getattr(ends, f)[ek]])
            for f in ("t", "piece", "s", "points", "normal", "branch", "residual_mm")
        }
        order = np.argsort(np.hypot(*merged["points"].T))
        env = type(env)(**{f: v[order] for f, v in merged.items()})
        keep = np.arange(len(order))  # every point kept, in order of radius (more points: shorter chords)
    pts = env.points[keep]
    pts.flags.writeable = False
    return ConjugateFlank(pts, env.t[keep], env.residual_mm[keep], sag, mot, env.normal[keep])


def _sagitta(env, keep, pieces, mot) -> float:
    """The largest distance between a chord and the exact envelope point at the middle of its two angles (the
    middles of one piece's chords in one call of :func:`envelope`)."""
    pts = env.points[keep]
    a, b = keep[:-1], keep[1:]
    same = env.piece[a] == env.piece[b]
    sag = 0.0
    for k in np.unique(env.piece[a][same]):
        idx = np.flatnonzero(same & (env.piece[a] == k))
        tm = 0.5 * (env.t[a[idx]] + env.t[b[idx]])
        e = envelope([pieces[k]], mot, tm)
        if not len(e.t):
            continue
        order = np.argsort(tm, kind="stable")
        pos = order[np.searchsorted(tm[order], e.t)]  # the chord whose middle angle each root belongs to
        mid = 0.5 * (pts[idx] + pts[idx + 1])
        dist = np.hypot(*(e.points - mid[pos]).T)
        best = np.full(len(idx), np.inf)
        np.minimum.at(best, pos, dist)
        # each chord's nearest root (the first in the envelope's order where two tie) against the chord
        hit = np.flatnonzero(dist == best[pos])
        hit = hit[np.argsort(pos[hit], kind="stable")]
        hit = hit[np.concatenate([[True], pos[hit][1:] != pos[hit][:-1]])]
        p0 = pts[idx[pos[hit]]]
        seg, d = pts[idx[pos[hit]] + 1] - p0, e.points[hit] - p0
        sag = max(
            sag, float((np.abs(seg[:, 0] * d[:, 1] - seg[:, 1] * d[:, 0]) / np.hypot(seg[:, 0], seg[:, 1])).max())
        )
    return sag
