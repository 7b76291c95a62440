"""The envelope of a flexspline tooth's flank in its motion relative to the rigid gear: the rigid tooth conjugate to it (docs/models.md 13).

A flank point ``p(s)`` (tooth frame, an exact piece) moves as ``X = R(rot(t))
p + shift(t)`` (:mod:`wgcad.envelope.motion`). It lies on the envelope when its
velocity is along the flank: ``g(s, t) = N . dX/dt = 0``, ``N = R J p'(s)``.
Since ``R J = J R`` the condition is

    g = rot' (p' . p) + (J R p') . shift',   dg/ds = rot' (p'' . p + p' . p') + (J R p'') . shift'

both in closed form from the piece and the motion. For each ``t`` every root
on every piece is bracketed on a sample of ``s`` and refined by Newton's method
(bisection when a step leaves its bracket; a root where the curve stops, an
involute's cusp on its base circle, satisfies the condition trivially and is
dropped); its residual is the distance along
the flank the next Newton step would still move the point, mm. Every root is a
branch of its own (numbered by ``s`` on its piece at that ``t``): which of them
bound the rigid tooth is the caller's choice, stated where it is made.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wgcad.plane import rotate

__all__ = ["EnvelopePoints", "envelope", "flank_pieces"]

#: Newton stops when the step along the flank is below this, mm
STEP_TOL = 1e-13
_MAX_ITER = 60


@dataclass(frozen=True, slots=True)
class EnvelopePoints:
    """Points of the envelope (read-only arrays, ``M`` of them).

    Attributes
    ----------
    t : (M,) float
        Motion parameter (the generator angle for :class:`~wgcad.envelope.motion.LawMotion`), rad.
    piece : (M,) int
        Index of the flank piece in contact.
    s : (M,) float
        The contact's parameter on that piece.
    points : (M, 2) float
        The envelope point in the rigid gear's frame, mm.
    normal : (M, 2) float
        The flank's unit normal there (rigid frame).
    branch : (M,) int
        The root's rank by ``s`` on its piece at that ``t``.
    residual_mm : (M,) float
        The distance along the flank the next Newton step would move the point.
    """

    t: np.ndarray
    piece: np.ndarray
    s: np.ndarray
    points: np.ndarray
    normal: np.ndarray
    branch: np.ndarray
    residual_mm: np.ndarray


def flank_pieces(gear, side: int = 1) -> list:
    """The pieces of one flank of ``gear``'s tooth (tooth frame): those of its pitch on the ``side`` (+1: y > 0)
    of the tooth's centre line, tip and root included."""
    out = []
    for p in gear.pieces:
        mid = p.point(np.array([0.5 * (p.t0 + p.t1)]))[0]
        if side * mid[1] > 0:
            out.append(p)
    return out


def _g(p, dp, ddp, rot, drot, dshift):
    """``g`` and ``dg/ds`` for points ``(..., 2)`` and the motion at matching ``(...)`` (``ddp`` None: ``g`` alone)."""
    c, s = np.cos(rot), np.sin(rot)
    # J R v = (-(R v)_y, (R v)_x)
    rdp_x, rdp_y = c * dp[..., 0] - s * dp[..., 1], s * dp[..., 0] + c * dp[..., 1]
    g = drot * np.einsum("...i,...i->...", dp, p) + (-rdp_y * dshift[..., 0] + rdp_x * dshift[..., 1])
    if ddp is None:
        return g, None
    rddp_x, rddp_y = c * ddp[..., 0] - s * ddp[..., 1], s * ddp[..., 0] + c * ddp[..., 1]
    dg = drot * (np.einsum("...i,...i->...", ddp, p) + np.einsum("...i,...i->...", dp, dp))
    dg = dg + (-rddp_y * dshift[..., 0] + rddp_x * dshift[..., 1])
    return g, dg


def _refine(piece, s_lo, s_hi, rot, drot, dshift):
    """Newton's method safeguarded by the brackets ``[s_lo, s_hi]`` (arrays), at the motion states given.

    Each root is done once its step is below :data:`STEP_TOL` (a Newton step that small is taken even where it
    leaves the bracket by rounding: bisecting there threw a converged root back to the middle of its bracket); the
    others go on, so a root comes out the same whichever roots it is refined with."""
    s = 0.5 * (s_lo + s_hi)
    lo, hi = np.minimum(s_lo, s_hi), np.maximum(s_lo, s_hi)
    sign_lo = np.sign(_g(piece.point(lo), piece.deriv(lo), None, rot, drot, dshift)[0])
    live = np.arange(len(s))
    for _ in range(_MAX_ITER):
        sl = s[live]
        p, dp, ddp = piece.point(sl), piece.deriv(sl), piece.deriv2(sl)
        g, dg = _g(p, dp, ddp, rot[live], drot[live], dshift[live])
        # keep the bracket: the side whose sign matches the low end moves up
        same = np.sign(g) == sign_lo[live]
        lo_l = np.where(same, sl, lo[live])
        hi_l = np.where(same, hi[live], sl)
        lo[live], hi[live] = lo_l, hi_l
        with np.errstate(divide="ignore", invalid="ignore"):
            new = sl - g / dg
        speed = np.hypot(dp[:, 0], dp[:, 1])
        done = np.abs(new - sl) * speed < STEP_TOL
        bad = ~done & (~np.isfinite(new) | (new <= lo_l) | (new >= hi_l))
        new = np.where(bad, 0.5 * (lo_l + hi_l), new)
        done |= np.abs(new - sl) * speed < STEP_TOL
        s[live] = new
        live = live[~done]
        if not live.size:
            break
    p, dp, ddp = piece.point(s), piece.deriv(s), piece.deriv2(s)
    g, dg = _g(p, dp, ddp, rot, drot, dshift)
    with np.errstate(divide="ignore", invalid="ignore"):
        residual = np.abs(g / dg) * np.linalg.norm(dp, axis=-1)
    return s, np.where(np.isfinite(residual), residual, np.inf)


def envelope(pieces, motion, t, samples: int = 256) -> EnvelopePoints:
    """Every contact of the flank ``pieces`` (tooth frame) with its envelope at each motion parameter in ``t``.

    ``samples`` points of ``s`` per piece bracket the roots (two roots closer than a sample step on one piece are
    missed: the flanks of a tooth are convex or concave over many samples).
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    rot, shift = motion.pose(t)
    drot, dshift = motion.rate(t)
    out = {k: [] for k in ("t", "piece", "s", "points", "normal", "branch", "residual_mm")}
    for k, pc in enumerate(pieces):
        sg = np.linspace(pc.t0, pc.t1, samples)
        P, dP = pc.point(sg), pc.deriv(sg)
        g, _ = _g(P[None], dP[None], None, rot[:, None], drot[:, None], dshift[:, None, :])
        sign = np.sign(g)
        ti, si = np.nonzero(sign[:, :-1] * sign[:, 1:] < 0)
        zi, zs = np.nonzero(sign == 0)  # a sample exactly on a root
        if len(zi):
            ti, si = np.concatenate([ti, zi]), np.concatenate([si, np.minimum(zs, samples - 2)])
        if not len(ti):
            continue
        s_root, res = _refine(pc, sg[si], sg[si + 1], rot[ti], drot[ti], dshift[ti])
        # one root per (t, bracket): duplicates from exact zeros merge
        key = np.round(s_root, 12)
        o = np.lexsort((key, ti))  # stable: the first of equal rows leads (np.unique would load numpy.ma)
        first = o[np.concatenate([[True], (np.diff(ti[o]) != 0) | (np.diff(key[o]) != 0)])]
        ti, s_root, res = ti[first], s_root[first], res[first]
        order = np.lexsort((s_root, ti))
        ti, s_root, res = ti[order], s_root[order], res[order]
        p, dp = pc.point(s_root), pc.deriv(s_root)
        # where the curve stops (an involute's cusp on its base circle) g vanishes for every t: no contact there
        moving = np.linalg.norm(dp, axis=-1) > 1e-9 * (1.0 + np.linalg.norm(p, axis=-1))
        if not moving.all():
            ti, s_root, res, p, dp = (a[moving] for a in (ti, s_root, res, p, dp))
        branch = np.zeros(len(ti), dtype=int)
        same = np.concatenate([[False], ti[1:] == ti[:-1]])
        for j in np.flatnonzero(same):
            branch[j] = branch[j - 1] + 1
        X = rotate(p, rot[ti]) + shift[ti]
        n = rotate(np.stack([dp[:, 1], -dp[:, 0]], axis=-1), rot[ti])  # R (dp_y, -dp_x)
        n /= np.linalg.norm(n, axis=-1)[:, None]
        for name, val in (
            ("t", t[ti]),
            ("piece", np.full(len(ti), k)),
            ("s", s_root),
            ("points", X),
            ("normal", n),
            ("branch", branch),
            ("residual_mm", res),
        ):
            out[name].append(val)
    arrays = {}
    for name, vals in out.items():
        if vals:
            a = np.concatenate(vals)
        else:
            a = np.empty((0, 2)) if name in ("points", "normal") else np.empty(0)
        a.flags.writeable = False
        arrays[name] = a
    return EnvelopePoints(**arrays)
