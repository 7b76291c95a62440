"""Torsional stiffness as catalogues state it: the wind-up curve fitted by three straight segments (T1, T2, K1, K2, K3), lost motion, natural frequency (docs/models.md 10.4)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi, sqrt

import numpy as np

__all__ = ["ThreeSegmentFit", "fit_three_segments", "natural_frequency_hz"]


@dataclass(frozen=True, slots=True)
class ThreeSegmentFit:
    """``theta(T) = theta0 + T/K1`` up to ``T1``, then slope ``1/K2`` to ``T2``, then ``1/K3`` (N m, rad, N m/rad).

    ``theta0`` is the fit's intercept, the wind-up offset on one side (the
    free play the fit extrapolates to zero torque, not the audit's no-load
    backlash, docs/glossary.md); ``max_error``/``rms_error`` the fit's
    residuals over the points, rad.
    """

    t1: float
    t2: float
    k1: float
    k2: float
    k3: float
    theta0: float
    max_error: float
    rms_error: float

    def wind_up(self, torque) -> np.ndarray:
        T = np.asarray(torque, dtype=float)
        return (
            self.theta0
            + np.minimum(T, self.t1) / self.k1
            + np.clip(T - self.t1, 0.0, self.t2 - self.t1) / self.k2
            + np.maximum(T - self.t2, 0.0) / self.k3
        )


def _basis(T, t1, t2):
    return np.column_stack([np.ones_like(T), np.minimum(T, t1), np.clip(T - t1, 0.0, t2 - t1), np.maximum(T - t2, 0.0)])


def fit_three_segments(torque, wind_up) -> ThreeSegmentFit:
    """Least-squares fit of the continuous three-segment form to a wind-up curve (``torque`` N m increasing from
    a small positive value, ``wind_up`` rad); the breakpoints are searched over the measured torques and refined on
    a fine grid between them (the segments' slopes and the offset are linear given the breakpoints)."""
    T = np.asarray(torque, dtype=float)
    th = np.asarray(wind_up, dtype=float)
    if len(T) < 5:
        raise ValueError("a three-segment fit needs at least 5 points")
    grid = np.linspace(T[0], T[-1], 4 * len(T) + 1)[1:-1]
    best = None
    for i, t1 in enumerate(grid):
        for t2 in grid[i + 1 :]:
            A = _basis(T, t1, t2)
            c, *_ = np.linalg.lstsq(A, th, rcond=None)
            r = A @ c - th
            e = float(r @ r)
            if best is None or e < best[0]:
                best = (e, t1, t2, c, r)
    _, t1, t2, c, r = best
    inv = c[1:]
    k = [1.0 / x if x > 0 else float("inf") for x in inv]
    return ThreeSegmentFit(
        t1=float(t1),
        t2=float(t2),
        k1=float(k[0]),
        k2=float(k[1]),
        k3=float(k[2]),
        theta0=float(c[0]),
        max_error=float(np.abs(r).max()),
        rms_error=float(sqrt(np.mean(r * r))),
    )


def natural_frequency_hz(stiffness_nm_per_rad: float, inertia_kg_m2: float) -> float:
    """First torsional natural frequency of an inertia on the drive's output, input held: ``sqrt(K/J) / 2 pi``, Hz."""
    return sqrt(stiffness_nm_per_rad / inertia_kg_m2) / (2.0 * pi)
