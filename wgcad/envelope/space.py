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

from .conjugate import envelope, flank_pieces
from .motion import LawMotion

__all__ = ["ConjugateFlank", "conjugate_flank"]


@dataclass(frozen=True)
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
    ``exact(i, j)``, the point's exact signed distance from the tooth at position ``j`` (negative: inside)."""
    import shapely

    geoms = shapely.polygons(polys)
    tree = shapely.STRtree(geoms)
    pts = shapely.points(x)
    ok = np.ones(len(x), dtype=bool)
    hits = tree.query(pts, predicate="intersects")
    for i, j in zip(*hits):
        if not ok[i]:
            continue
        depth = shapely.distance(pts[i], geoms[j].exterior)
        if depth > tol or exact(i, j) < -1e-9:
            ok[i] = False
    return ok


def _side_distance(piece, s0, x, rot, shift):
    """Signed distance (along ``(p'_y, -p'_x)``, the right of the piece's direction) of points ``x (M, 2)`` from ``piece`` placed at
    ``(rot, shift)`` (arrays), by Newton's projection started at ``s0``."""
    c, sn = np.cos(rot), np.sin(rot)

    def place(v):
        return np.stack([c * v[:, 0] - sn * v[:, 1], sn * v[:, 0] + c * v[:, 1]], axis=-1)

    s = np.array(s0, dtype=float)
    lo, hi = min(piece.t0, piece.t1), max(piece.t0, piece.t1)
    for _ in range(30):
        X = place(piece.point(s)) + shift
        d1, d2 = place(piece.deriv(s)), place(piece.deriv2(s))
        f = np.einsum("ij,ij->i", X - x, d1)
        df = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", X - x, d2)
        s = np.clip(s - f / df, lo, hi)
    X = place(piece.point(s)) + shift
    d1 = place(piece.deriv(s))
    n = np.stack([d1[:, 1], -d1[:, 0]], axis=-1) / np.linalg.norm(d1, axis=-1)[:, None]
    return np.einsum("ij,ij->i", x - X, n)


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


def _boundary(env, idx, t, polys, tol, pieces, mot):
    idx = idx[_locally_outside(env, idx, pieces, mot)]
    x = env.points[idx]
    starts = [np.linspace(p.t0, p.t1, 64) for p in pieces]

    def exact(i, j):
        rot, shift = mot.pose(np.array([t[j]]))
        best = np.inf
        for p, sg in zip(pieces, starts):
            c, sn = np.cos(rot[0]), np.sin(rot[0])
            P = p.point(sg) @ np.array([[c, sn], [-sn, c]]) + shift[0]
            s0 = sg[np.argmin(np.hypot(*(P - x[i]).T))]
            d = _side_distance(p, np.array([s0]), x[i : i + 1], rot, shift)[0]
            if abs(d) < abs(best):
                best = d
        return best

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
    keep = _boundary(env, rigid_side(env), t, polys, tol, pieces, mot)
    if len(keep) < 2:
        raise ValueError("the flexspline tooth never touches the rigid tooth's side of its path: no conjugate flank")
    # again, finely, over the stretch of the pass where the flank is touched, until the chords lie within
    # sagitta_tol of the envelope (doubling the angles up to 64 times the first count)
    dt = t[1] - t[0]
    lo, hi = env.t[keep].min() - 3 * dt, env.t[keep].max() + 3 * dt
    n = points
    while True:
        env = envelope(pieces, mot, np.linspace(lo, hi, n))
        keep = _boundary(env, rigid_side(env), t, polys, tol, pieces, mot)
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
    ek = _boundary(ends, rigid_side(ends), t, polys, tol, pieces, mot)
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
    """The largest distance between a chord and the exact envelope point at the middle of its two angles."""
    pts = env.points[keep]
    sag = 0.0
    for i, (a, b) in enumerate(zip(keep[:-1], keep[1:])):
        if env.piece[a] != env.piece[b]:
            continue
        e = envelope([pieces[env.piece[a]]], mot, np.array([0.5 * (env.t[a] + env.t[b])]))
        if not len(e.t):
            continue
        seg = pts[i + 1] - pts[i]
        x = e.points[np.argmin(np.hypot(*(e.points - 0.5 * (pts[i] + pts[i + 1])).T))]
        sag = max(sag, abs(float(seg[0] * (x - pts[i])[1] - seg[1] * (x - pts[i])[0])) / float(np.hypot(*seg)))
    return sag
