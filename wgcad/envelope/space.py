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

import numpy as np

from wgcad.plane import rotate

from ..records import record
from .conjugate import envelope, flank_pieces
from .motion import LawMotion

__all__ = ["ConjugateFlank", "conjugate_flank"]


@record(frozen=True)
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
    all in one call."""
    import shapely

    geoms = shapely.polygons(polys)
    tree = shapely.STRtree(geoms)
    pts = shapely.points(x)
    ok = np.ones(len(x), dtype=bool)
    hi, hj = tree.query(pts, predicate="intersects")
    if not hi.size:
        return ok
    depth = shapely.distance(pts[hi], shapely.get_exterior_ring(geoms[hj]))
    # covered, or within the chord tolerance of being covered by a sampled position: between the pass's
    # positions (2e-3 rad apart) a tooth corner sweeps farther than the exact test at the samples sees (held
    # to the strict test, the cycloidal flank kept points below the tip's path, crossed by 0.17 um)
    ok[hi[depth > tol]] = False
    ask = np.flatnonzero((depth <= tol) & ok[hi])
    if ask.size:
        ok[hi[ask[exact(hi[ask], hj[ask]) > -tol]]] = False
    return ok


def _side_distance(piece, s0, x, rot, shift, with_gap: bool = False):
    """Signed distance of points ``x (M, 2)`` from ``piece`` placed at ``(rot, shift)`` (arrays), positive on the
    tooth's side, by Newton's projection started at ``s0``.

    A tooth's pieces run from its centre line toward the space with the material on their left; the parameter
    may run either way (an involute's roll parameter falls toward the root, an arc's angle may rise), so the
    side is taken from the direction of travel, ``t0 -> t1``, not from ``p'`` alone (a double-arc flank, whose
    angles rise, read every point on the wrong side)."""

    def place(v):
        return rotate(v, rot)

    s = np.array(s0, dtype=float)
    lo, hi = min(piece.t0, piece.t1), max(piece.t0, piece.t1)
    for _ in range(30):
        X = place(piece.point(s)) + shift
        d1, d2 = place(piece.deriv(s)), place(piece.deriv2(s))
        f = np.einsum("ij,ij->i", X - x, d1)
        df = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", X - x, d2)
        s_new = np.clip(s - f / df, lo, hi)
        if np.array_equal(s_new, s):  # converged to the last bit: the remaining steps would change nothing
            break
        s = s_new
    X = place(piece.point(s)) + shift
    d1 = place(piece.deriv(s))
    travel = 1.0 if piece.t1 >= piece.t0 else -1.0
    n = -travel * np.stack([d1[:, 1], -d1[:, 0]], axis=-1) / np.linalg.norm(d1, axis=-1)[:, None]  # left of travel
    side = np.einsum("ij,ij->i", x - X, n)
    return (side, np.hypot(*(x - X).T)) if with_gap else side


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
        # the side of the nearest point of the flank (by distance: a projection clamped to a piece's end measures
        # along that end's normal, which can point either way for a point off the piece); every pair at once,
        # in chunks that keep the start grid's arrays small
        out = np.empty(len(I))
        for a in range(0, len(I), 4096):
            i, j = I[a : a + 4096], J[a : a + 4096]
            rot, shift = mot.pose(t[j])
            c, sn = np.cos(rot)[:, None], np.sin(rot)[:, None]
            best, gap = np.full(len(i), np.inf), np.full(len(i), np.inf)
            for p, sg in zip(outline, starts):
                P = p.point(sg)
                px = P[None, :, 0] * c - P[None, :, 1] * sn + shift[:, None, 0]
                py = P[None, :, 0] * sn + P[None, :, 1] * c + shift[:, None, 1]
                s0 = sg[np.argmin(np.hypot(px - x[i, None, 0], py - x[i, None, 1]), axis=1)]
                d, g = _side_distance(p, s0, x[i], rot, shift, with_gap=True)
                closer = g < gap
                best[closer], gap[closer] = d[closer], g[closer]
            out[a : a + 4096] = best
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
        for j in np.flatnonzero(np.isfinite(best)):
            x = e.points[(pos == j) & (dist == best[j])][0]
            seg = pts[idx[j] + 1] - pts[idx[j]]
            d = x - pts[idx[j]]
            sag = max(sag, abs(float(seg[0] * d[1] - seg[1] * d[0])) / float(np.hypot(*seg)))
    return sag
