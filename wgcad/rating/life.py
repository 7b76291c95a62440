"""Basic rating life L10 of the wave generator's flexible bearing from its ball loads (docs/models.md 10.5).

The two-wave ball loads of a flexible bearing have no resultant, so ISO 281's
equivalent radial load does not apply; its basis does. Lundberg and
Palmgren's raceway ratings (the formula behind ISO 281's ``C_r``, with its
factor ``b_m = 1.3`` for today's steels) for a point contact:

    Q_c = b_m 98.1 (2f/(2f - 1))^0.41 (1 -+ g)^1.39 / (1 +- g)^(1/3) (g/cos a)^0.3 D^1.8 Z^(-1/3)   [N, mm]

(upper signs the inner raceway; ``g = D cos a / d_m``), each raceway's life
``(Q_c / Q_e)^3`` in millions of revolutions with the mean ball load
``Q_e`` of the ring: cubic for the ring the load turns against, ``10/3``
power for the ring the load stands still on, and the bearing's life
``(L_i^(-10/9) + L_o^(-10/9))^(-9/10)`` (Harris and Kotzalas, Rolling Bearing
Analysis, ch. 8). In a wave generator the load pattern turns with the cam, so
it stands on the inner ring and turns against the outer one, at the input
speed relative to the flexspline.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["B_M", "raceway_ratings", "BearingLife", "bearing_life"]

#: ISO 281:2007's rating factor for radial ball bearings of today's steels
B_M = 1.3


def raceway_ratings(ball_d: float, pitch_d: float, balls: int, f_inner: float, f_outer: float, contact_deg=0.0):
    """Basic dynamic ratings ``(Q_ci, Q_co)`` of the inner and outer raceways, N (formula in the module doc)."""
    cos_a = np.cos(np.deg2rad(contact_deg))
    g = ball_d * cos_a / pitch_d
    common = B_M * 98.1 * (g / cos_a) ** 0.3 * ball_d**1.8 * balls ** (-1.0 / 3.0)
    qi = common * (2 * f_inner / (2 * f_inner - 1)) ** 0.41 * (1 - g) ** 1.39 / (1 + g) ** (1.0 / 3.0)
    qo = common * (2 * f_outer / (2 * f_outer - 1)) ** 0.41 * (1 + g) ** 1.39 / (1 - g) ** (1.0 / 3.0)
    return float(qi), float(qo)


@dataclass(frozen=True, slots=True)
class BearingLife:
    """L10 of the flexible bearing.

    Attributes
    ----------
    l10_mrev : float
        Millions of revolutions of the cam relative to the flexspline.
    l10_h : float
        Hours at ``speed_rpm`` (input) and the drive's ratio.
    q_inner, q_outer : float
        Mean ball loads of the inner (10/3 power) and outer (cubic) ring, N.
    q_ci, q_co : float
        Raceway ratings, N.
    """

    l10_mrev: float
    l10_h: float
    q_inner: float
    q_outer: float
    q_ci: float
    q_co: float
    relative_rpm: float


def bearing_life(ball_loads, ball_d: float, pitch_d: float, conformity: float, speed_rpm: float, ratio: float):
    """L10 from the ball loads (N) of one state; ``ratio`` the input over the output speed (signed: the
    flexspline's turn adds to or takes from the cam's relative speed)."""
    Q = np.maximum(np.asarray(ball_loads, dtype=float), 0.0)
    Z = len(Q)
    qi_c, qo_c = raceway_ratings(ball_d, pitch_d, Z, conformity, conformity)
    q_in = float(np.mean(Q ** (10.0 / 3.0)) ** 0.3)
    q_out = float(np.mean(Q**3) ** (1.0 / 3.0))
    if q_in <= 0.0:
        l10 = float("inf")
    else:
        li = (qi_c / q_in) ** 3
        lo = (qo_c / q_out) ** 3
        l10 = float((li ** (-10.0 / 9.0) + lo ** (-10.0 / 9.0)) ** (-0.9))
    rel = abs(speed_rpm * (1.0 - 1.0 / ratio))
    return BearingLife(l10, l10 * 1e6 / (60.0 * rel), q_in, q_out, qi_c, qo_c, rel)
