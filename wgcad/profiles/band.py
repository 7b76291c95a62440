"""Polylines of exact pieces that deviate from the curve by at most a tolerance on either side (a symmetric chord band).

Chords through points of a curve all lie on its concave side: a tooth drawn
that way is systematically thinner (convex flanks) or its space narrower.
Here the interior vertices are moved off the curve to its convex side, so
the polyline crosses the curve and its error is split: each interior
vertex moves out by half the larger sagitta of its two chords, so
the curve lies at most ``tol`` inside the polyline (at the vertices) and at
most ``tol`` outside it (mid-chord), with chords up to ``sqrt(2)`` times
longer than one-sided ones of the same tolerance. End points of a piece stay on the curve (they are shared corners).
"""

from __future__ import annotations

import numpy as np

from .. import constants
from .sampling import chord_deviation, sample_curve

__all__ = ["band_points", "band_outline", "band_deviation", "gear_band_outline"]


def _offset_dir(piece, t):
    """Unit vectors ``(n, 2)`` toward the convex side (away from the centre of curvature)."""
    d1, d2 = piece.deriv(t), piece.deriv2(t)
    tang = d1 / np.maximum(np.hypot(d1[:, 0], d1[:, 1]), 1e-300)[:, None]
    perp = d2 - (d2 * tang).sum(-1)[:, None] * tang  # curvature vector (toward the centre)
    L = np.hypot(perp[:, 0], perp[:, 1])
    out = -perp / np.maximum(L, 1e-300)[:, None]
    out[L < 1e-12] = 0.0  # straight: nothing to split
    return out


def band_deviation(piece, pts: np.ndarray, n: int = 2001) -> tuple[float, float]:
    """Largest distance of the curve outside and inside the polyline ``pts`` of one piece, mm (dense check)."""
    t = np.linspace(piece.t0, piece.t1, n)
    c = piece.point(t)
    conv = _offset_dir(piece, t)
    # nearest segment of each curve point
    a, b = pts[:-1], pts[1:]
    best = np.full(n, np.inf)
    sign = np.zeros(n)
    for i in range(len(a)):
        d = chord_deviation(c, np.broadcast_to(a[i], c.shape), np.broadcast_to(b[i], c.shape))
        ab = b[i] - a[i]
        u = np.clip(((c - a[i]) @ ab) / max(ab @ ab, 1e-300), 0.0, 1.0)
        foot = a[i] + u[:, None] * ab
        s = np.sign(((c - foot) * conv).sum(-1))  # > 0: the curve lies on its convex side of the polyline
        upd = d < best
        best[upd], sign[upd] = d[upd], s[upd]
    outside = float(np.max(np.where(sign > 0, best, 0.0)))
    inside = float(np.max(np.where(sign <= 0, best, 0.0)))
    return outside, inside


def band_points(piece, tol: float) -> np.ndarray:
    """Vertices ``(n, 2)`` of ``piece`` whose polyline stays within ``tol`` of it on either side."""
    f = piece.point
    # 1.6 tol: margin for the parameter recovery below and for sagittas that change from chord to
    # chord (cycloids near the pitch-point cusp)
    pts = sample_curve(f, piece.t0, piece.t1, 1.6 * tol)
    if len(pts) <= 2:
        return sample_curve(f, piece.t0, piece.t1, tol)
    # the parameters of the sampled vertices (sample_curve returns points only): re-sample them
    # on the same bisection: recover t by projecting onto a dense grid
    tg = np.linspace(piece.t0, piece.t1, 64 * len(pts))
    grid = f(tg)
    idx = np.argmin(((pts[:, None, :] - grid[None]) ** 2).sum(-1), axis=1)
    t = tg[idx]
    t[0], t[-1] = piece.t0, piece.t1
    # the chords next to the ends start on the curve (a corner, not moved): halve them
    t = np.concatenate([[t[0], 0.5 * (t[0] + t[1])], t[1:-1], [0.5 * (t[-2] + t[-1]), t[-1]]])
    # each chord's sagitta (largest of 7 curve points to the chord; where curvature piles up at one
    # end, a cycloid's cusp, the middle is not the farthest), chords bisected until within 1.6 tol
    for _ in range(30):
        out = f(t)
        sag = np.zeros(len(t) - 1)
        for fr in np.linspace(0.125, 0.875, 7):
            sag = np.maximum(sag, chord_deviation(f(t[:-1] + fr * (t[1:] - t[:-1])), out[:-1], out[1:]))
        lim = np.full(len(sag), 1.6 * tol)
        lim[[0, -1]] = 0.8 * tol  # the end chords keep one end on the curve: their whole sagitta counts
        bad = np.nonzero(sag > lim)[0]
        if bad.size == 0:
            break
        t = np.insert(t, bad + 1, 0.5 * (t[bad] + t[bad + 1]))
    # each interior vertex moved out: the polyline then runs about half in, half out
    inner = np.arange(1, len(t) - 1)
    # half the larger sagitta of its two chords: every chord's vertices are then out by at least half
    # its own sagitta (mid-chord error <= s/2 <= 0.8 tol inside) and at most 0.8 tol out
    shift = 0.5 * np.maximum(sag[:-1], sag[1:])
    out[inner] += shift[:, None] * _offset_dir(piece, t[inner])
    return out


def band_outline(pieces, tol: float) -> np.ndarray:
    """Closed polyline ``(N, 2)`` of a path of pieces (e.g. :meth:`wgcad.profiles.gear.Gear.outline_pieces`), symmetric band ``tol``."""
    parts = [band_points(p, tol)[:-1] for p in pieces]
    return np.ascontiguousarray(np.concatenate(parts))


def gear_band_outline(gear, tol: float | None = None, offset: float = 0.0) -> np.ndarray:
    """The whole toothed boundary of ``gear`` in a symmetric band ``tol`` (default the gear's chord tolerance).

    Same order, start and orientation as :attr:`wgcad.profiles.gear.Gear.outline`
    (one pitch from the exact pieces, turned by ``k 2 pi/z + phase``), so an
    export can use either; vertices closer than
    :data:`wgcad.constants.MIN_VERTEX_SPACING` to the previous one are dropped
    (they would merge in a float32 STL). ``offset`` (mm): every pitch moved
    that far out along its tooth's centre line (a face-modified section,
    docs/models.md 13.4; consecutive pitches are then joined by a chord of
    ``2 offset sin(pi/z)`` at the middle of the root).
    """
    tol = gear.tol if tol is None else float(tol)
    one = band_outline(gear.pieces, tol)
    step = np.hypot(*np.diff(np.vstack([one, one[:1]]), axis=0).T)
    one = one[np.concatenate([[True], step[:-1] > constants.MIN_VERTEX_SPACING])] if len(one) > 2 else one
    if offset:
        one = one + np.array([float(offset), 0.0])
    z = gear.spec.z
    ang = np.arange(z) * 2.0 * np.pi / z + gear.spec.phase
    c, s = np.cos(ang)[:, None], np.sin(ang)[:, None]
    x = c * one[None, :, 0] - s * one[None, :, 1]
    y = s * one[None, :, 0] + c * one[None, :, 1]
    out = np.stack([x, y], axis=-1).reshape(-1, 2)
    out.setflags(write=False)
    return out
