"""Discretisation of curves to a chord tolerance: adaptive for smooth curves, closed form for arcs."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["sample_curve", "arc_points", "chord_deviation", "polar"]


def polar(radius, angle) -> np.ndarray:
    """Points ``(..., 2)`` from polar coordinates (broadcast)."""
    radius = np.asarray(radius, dtype=float)
    angle = np.asarray(angle, dtype=float)
    return np.stack(np.broadcast_arrays(radius * np.cos(angle), radius * np.sin(angle)), axis=-1)


def chord_deviation(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of points ``p (n, 2)`` from the segments ``a -> b`` (each ``(n, 2)``)."""
    ab = b - a
    ap = p - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(L2 > 0, np.einsum("ij,ij->i", ap, ab) / L2, 0.0)
    u = np.clip(u, 0.0, 1.0)
    d = ap - u[:, None] * ab
    return np.hypot(d[:, 0], d[:, 1])


def sample_curve(
    f: Callable[[np.ndarray], np.ndarray],
    t0: float,
    t1: float,
    tol: float,
    n0: int = 4,
    max_iter: int = 60,
) -> np.ndarray:
    """Sample a smooth parametric curve so every chord stays within ``tol`` of it.

    Segments are bisected until the curve points at 1/4, 1/2 and 3/4 of each
    parameter interval lie within ``tol`` of the chord; for curves whose
    curvature varies slowly over a segment (involutes, cycloids, arcs) the
    largest deviation sits near the middle, so this bounds the chord error.

    Parameters
    ----------
    f : callable
        Vectorised curve, ``(n,) float -> (n, 2) float``.
    t0, t1 : float
        Parameter range; the result runs from ``f(t0)`` to ``f(t1)``.
    tol : float
        Chord tolerance, mm.

    Returns
    -------
    points : (n, 2) float
    """
    if t0 == t1:
        return f(np.array([t0], dtype=float))
    t = np.linspace(t0, t1, n0 + 1)
    p = f(t)
    for _ in range(max_iter):
        dt = t[1:] - t[:-1]
        worst = np.zeros(len(dt))
        for frac in (0.25, 0.5, 0.75):
            q = f(t[:-1] + frac * dt)
            worst = np.maximum(worst, chord_deviation(q, p[:-1], p[1:]))
        bad = np.nonzero(worst > tol)[0]
        if bad.size == 0:
            return p
        tm = t[bad] + 0.5 * dt[bad]
        t = np.insert(t, bad + 1, tm)
        p = np.insert(p, bad + 1, f(tm), axis=0)
    raise ArithmeticError("sample_curve did not converge")  # pragma: no cover


def arc_points(center, radius: float, a0: float, a1: float, tol: float) -> np.ndarray:
    """Points ``(n, 2)`` of the circular arc from angle ``a0`` to ``a1`` (either direction).

    The count is the smallest that keeps the sagitta within ``tol``;
    both end points are included exactly.
    """
    span = abs(a1 - a0)
    if radius <= tol or span == 0.0:
        n = 1
    else:
        step = 2.0 * np.arccos(max(-1.0, 1.0 - tol / radius))
        n = max(1, int(np.ceil(span / step)))
    a = np.linspace(a0, a1, n + 1)
    return np.asarray(center, dtype=float) + polar(radius, a)
