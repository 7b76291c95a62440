"""Friction torque of the wave-generator bearing from its ball loads: Palmgren's load and viscous terms
(docs/models.md 10.8).

Palmgren (1959), as given by Harris & Kotzalas, *Rolling Bearing Analysis* (5th ed., 2007), the friction chapter:

    M = M1 + M0,   M1 = f1 P1 dm,   f1 = z (P1 / C0)^y                              (load term)
    M0 = 1e-7 f0 (nu n)^(2/3) dm^3  (nu n >= 2000),   M0 = 160e-7 f0 dm^3  (below)   (viscous term)

with ``M`` in N mm, ``P1`` N, ``dm`` (pitch diameter) mm, ``nu`` the lubricant's kinematic viscosity mm^2/s,
``n`` the rings' relative speed rpm; for radial deep-groove ball bearings ``z = 0.0004-0.0006`` (0.0005 taken),
``y = 0.55``.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import gamma, sqrt

import numpy as np

from wgcad.elastic.bearing import STATIC_PRESSURE_LIMIT_MPA

__all__ = [
    "BearingFriction",
    "palmgren_torque",
    "static_rating",
    "bearing_friction",
    "PALMGREN_Z",
    "PALMGREN_Y",
    "STRIBECK_SUM",
]

#: Palmgren's load-term factor ``f1 = z (P1/C0)^y`` of radial deep-groove ball bearings (z 0.0004-0.0006: the middle)
PALMGREN_Z = 0.0005
PALMGREN_Y = 0.55


def _cos_integral(p: float) -> float:
    """``int_{-pi/2}^{pi/2} cos^p``, the Beta function's closed form."""
    return sqrt(np.pi) * gamma(0.5 * (p + 1.0)) / gamma(0.5 * p + 1.0)


#: sum of the ball loads over the radial load of a rigid radial ball bearing at zero clearance (Stribeck's
#: distribution, ``Q = Q_max cos^1.5 psi`` over half the balls): 1.216
STRIBECK_SUM = _cos_integral(1.5) / _cos_integral(2.5)
#: ISO 76: a radial ball bearing's static rating C0 is the radial load whose most loaded ball, ``5 C0 / Z``, reaches
#: the static pressure limit
_ISO76_BALL = 5.0


@dataclass(frozen=True, slots=True)
class BearingFriction:
    """Palmgren's friction torque of one state, N mm (on the rings, against their relative rotation)."""

    load: float
    viscous: float
    p1_n: float
    f1: float

    @property
    def total(self) -> float:
        return self.load + self.viscous


def static_rating(balls: int, pressure_coef: float) -> float:
    """The static rating ``C0`` (N) of ISO 76's definition from the bearing's own Hertz contact: the radial load
    ``Z Q_s / 5`` whose most loaded ball ``Q_s`` reaches 4200 MPa (``p_max = q Q^(1/3)``, the elastic model's)."""
    q_s = (STATIC_PRESSURE_LIMIT_MPA / pressure_coef) ** 3
    return balls * q_s / _ISO76_BALL


def palmgren_torque(
    p1_n: float, c0_n: float, dm_mm: float, nu_cst: float, n_rpm: float, f0: float, z: float = PALMGREN_Z
) -> BearingFriction:
    """Palmgren's ``M1 + M0`` (N mm) for equivalent load ``p1_n``, static rating ``c0_n``, pitch diameter ``dm_mm``,
    viscosity ``nu_cst`` (mm^2/s), relative speed ``n_rpm`` (0: at rest, no viscous term), lubrication factor ``f0``
    and load factor ``z``."""
    p1 = max(float(p1_n), 0.0)
    f1 = z * (p1 / c0_n) ** PALMGREN_Y
    load = f1 * p1 * dm_mm
    vn = nu_cst * abs(n_rpm)
    if n_rpm == 0:
        viscous = 0.0
    elif vn >= 2000.0:
        viscous = 1e-7 * f0 * vn ** (2.0 / 3.0) * dm_mm**3
    else:
        viscous = 160e-7 * f0 * dm_mm**3
    return BearingFriction(float(load), float(viscous), p1, float(f1))


def bearing_friction(
    ball_loads, balls: int, pressure_coef: float, dm_mm: float, nu_cst: float, n_rpm: float, f0: float
) -> BearingFriction:
    """The flexible bearing's Palmgren torque from its ball loads (N).

    Palmgren's load term is written for a bearing under one radial load; the cam loads the balls in two (or more)
    waves with no resultant. ``P1`` is taken as the radial load of a rigid bearing whose balls carry the same total
    (``sum Q / STRIBECK_SUM``): the rolling loss grows with the ball loads, not with their resultant.
    """
    q = np.maximum(np.asarray(ball_loads, dtype=float), 0.0)
    p1 = float(q.sum()) / STRIBECK_SUM
    return palmgren_torque(p1, static_rating(balls, pressure_coef), dm_mm, nu_cst, n_rpm, f0)
