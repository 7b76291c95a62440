"""The flexible bearing: balls as Hertz point contacts (P ~ delta^(3/2)) with radial clearance (docs/models.md 4.1)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from wgcad.errors import DesignError

__all__ = ["HertzPoint", "ball_contact", "FlexibleBearing", "STATIC_PRESSURE_LIMIT_MPA"]

#: Largest Hertz pressure (MPa) a ball may see: the static limit of ISO 76 for
#: ball bearings (4200 MPa), above which the raceways take permanent dents.
STATIC_PRESSURE_LIMIT_MPA = 4200.0


@dataclass(frozen=True, slots=True)
class HertzPoint:
    """One elliptical Hertz contact, Hamrock & Brewe (1983) approximations (docs/models.md 4.1).

    ``delta = c P^(2/3)`` (mm, N) and ``p_max = q P^(1/3)`` (MPa) with the
    constants from the curvature sums ``1/Rx, 1/Ry`` (1/mm) and the plane-strain
    modulus ``E' = E/(1 - nu^2)`` (MPa, both bodies of one material).
    """

    c: float
    q: float

    @classmethod
    def from_curvatures(cls, inv_rx: float, inv_ry: float, e_prime: float) -> HertzPoint:
        if not (inv_rx > 0 and inv_ry > 0):
            raise DesignError(
                "bearing.groove_conformity",
                "the ball-raceway curvature sums must be positive (conformity > 0.5, ball smaller than the ring)",
            )
        rx, ry = 1.0 / inv_rx, 1.0 / inv_ry
        R = 1.0 / (inv_rx + inv_ry)
        alpha = ry / rx
        k = 1.0339 * alpha**0.6360
        e_ell = 1.0003 + 0.5968 / alpha
        f_ell = 1.5277 + 0.6023 * np.log(alpha)
        # delta = F [ (9 / (2 E R)) (P / (pi k E'))^2 ]^(1/3)
        c = f_ell * (9.0 / (2.0 * e_ell * R) / (pi * k * e_prime) ** 2) ** (1.0 / 3.0)
        # semi-axes a = (6 k^2 E P R / (pi E'))^(1/3), b = (6 E P R / (pi k E'))^(1/3); p_max = 3P / (2 pi a b)
        ab = (6.0 * k**2 * e_ell * R / (pi * e_prime)) ** (1 / 3) * (6.0 * e_ell * R / (pi * k * e_prime)) ** (1 / 3)
        q = 3.0 / (2.0 * pi * ab)
        return cls(float(c), float(q))


def ball_contact(
    ball_d: float, race_r_outer: float, conformity: float, e_prime: float
) -> tuple[HertzPoint, HertzPoint]:
    """Inner (convex race on the cam) and outer (concave race) contacts of one ball.

    ``race_r_outer`` is the outer raceway's radius at the ball contact (mm);
    the inner raceway is one ball diameter smaller; both grooves have radius
    ``conformity * ball_d``.
    """
    inv_ball = 2.0 / ball_d
    inv_groove = 1.0 / (conformity * ball_d)
    r_in = race_r_outer - ball_d
    if r_in <= 0:
        raise DesignError(
            "bearing.ball_diameter_mm", f"{ball_d:g} mm leaves no inner raceway inside {race_r_outer:g} mm"
        )
    inner = HertzPoint.from_curvatures(inv_ball + 1.0 / r_in, inv_ball - inv_groove, e_prime)
    outer = HertzPoint.from_curvatures(inv_ball - 1.0 / race_r_outer, inv_ball - inv_groove, e_prime)
    return inner, outer


@dataclass(frozen=True, slots=True)
class FlexibleBearing:
    """Balls between the cam and the (merged) outer ring: angles, gap and load-approach law.

    Attributes
    ----------
    psi : (Z,) float
        Ball angles from the generator's major axis, rad.
    clearance : float
        Radial gap at every ball when the cam is centred, mm: the bearing's
        internal clearance plus the gap between its outer ring and the
        flexspline bore, in series (docs/models.md 4.1).
    c : float
        ``delta = c P^(2/3)``: the ball's total approach (both raceways), mm/N^(2/3).
    q : float
        ``p_max = q P^(1/3)`` at the more loaded (inner) raceway, MPa/N^(1/3).
    """

    psi: np.ndarray
    clearance: float
    c: float
    q: float

    def approach(self, P):
        """Ball approach ``delta(P) = c P^(2/3)``, mm."""
        return self.c * np.maximum(np.asarray(P, dtype=float), 0.0) ** (2.0 / 3.0)

    def secant(self, P, p_floor: float):
        """Secant compliance ``delta(P)/P`` (mm/N), with ``P`` floored at ``p_floor`` N (finite at zero load)."""
        P = np.maximum(np.asarray(P, dtype=float), p_floor)
        return self.c * P ** (-1.0 / 3.0)

    def tangent(self, P, p_floor: float):
        """Newton linearisation of the approach about ``P``: ``delta ~ offset + slope P`` (mm, mm/N).

        Tangent where ``P > p_floor``; the secant through zero at ``p_floor``
        otherwise (no offset, so an open contact stays exactly open).
        """
        P = np.asarray(P, dtype=float)
        on = P > p_floor
        Pf = np.where(on, P, p_floor)
        lam = self.c * Pf ** (2.0 / 3.0)
        slope = np.where(on, (2.0 / 3.0) * lam / Pf, lam / Pf)
        return np.where(on, lam / 3.0, 0.0), slope

    def pressure(self, P):
        """Largest Hertz pressure at each ball, MPa."""
        return self.q * np.maximum(np.asarray(P, dtype=float), 0.0) ** (1.0 / 3.0)

    def check(self, P) -> None:
        """Raise :class:`DesignError` when a ball load exceeds the static pressure limit."""
        p = self.pressure(P)
        if p.size and p.max() > STATIC_PRESSURE_LIMIT_MPA:
            i = int(np.argmax(p))
            raise DesignError(
                "bearing.ball_diameter_mm",
                f"the bearing cannot carry the load: ball {i} takes {float(np.asarray(P)[i]):.0f} N, Hertz pressure "
                f"{p[i]:.0f} MPa > {STATIC_PRESSURE_LIMIT_MPA:.0f} MPa (ISO 76 static limit); use larger or more balls",
            )
