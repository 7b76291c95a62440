"""Fatigue of the flexspline: the endurance limit with its modifying factors, notch sensitivity, Goodman's safety factor (docs/models.md 10.3).

Every factor is Shigley's (Mechanical Engineering Design, 10th ed., ch. 6)
and is reported with the figure it gives:
``S_e = k_a k_b k_e S_e'``; ``k_a = a S_u^b`` (table 6-2); ``k_b`` for a
rectangular section in bending, equivalent diameter ``0.808 sqrt(h b)``, held
at 1 below 7.62 mm rather than the formula's rise above 1; ``k_e = 1 - 0.08 z``
with ``z`` the standard normal quantile of the reliability; the notch
sensitivity of Neuber ``q = 1 / (1 + sqrt(a/r))`` with Kuhn and Hardraht's
``sqrt(a)`` for steel in bending (eq. 6-35a), ``K_f = 1 + q (K_t - 1)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import sqrt
from statistics import NormalDist

from wgcad.errors import DesignError

__all__ = ["Strength", "strength", "goodman_safety", "SURFACE_FACTORS"]

#: surface factor ``k_a = a S_u^b`` (S_u in MPa), Shigley table 6-2
SURFACE_FACTORS = {
    "ground": (1.58, -0.085),
    "machined": (4.51, -0.265),
    "hot_rolled": (57.7, -0.718),
    "forged": (272.0, -0.995),
}
_KPSI_PER_MPA = 1.0 / 6.894757
_MM_PER_IN = 25.4


@dataclass(frozen=True, slots=True)
class Strength:
    """The flexspline material's strengths and fatigue factors (MPa, dimensionless)."""

    ultimate: float
    yield_: float
    endurance_specimen: float
    k_a: float
    k_b: float
    k_e: float
    surface_finish: str
    reliability: float
    assumed: tuple

    @property
    def endurance(self) -> float:
        """The modified endurance limit ``S_e = k_a k_b k_e S_e'``, MPa."""
        return self.k_a * self.k_b * self.k_e * self.endurance_specimen

    def notch_sensitivity(self, radius: float) -> float:
        """Neuber's ``q`` for a notch of ``radius`` (mm) in bending, steel (Kuhn and Hardraht's constant)."""
        su = min(max(self.ultimate * _KPSI_PER_MPA, 50.0), 250.0)  # the fit's range, kpsi
        sqrt_a = 0.246 - 3.08e-3 * su + 1.51e-5 * su**2 - 2.67e-8 * su**3  # sqrt(in)
        return 1.0 / (1.0 + sqrt_a / sqrt(radius / _MM_PER_IN))


def _size_factor(h: float, b: float) -> float:
    d = 0.808 * sqrt(h * b)
    return min(1.0, 1.24 * d**-0.107) if d <= 51.0 else 1.51 * d**-0.157


def strength(material, section_h: float, section_b: float) -> Strength:
    """The strengths of ``[material]`` for a rim section ``section_h`` thick and ``section_b`` wide (mm).

    Raises :class:`DesignError` when ``ultimate_strength_mpa`` is missing or
    the strengths contradict each other.
    """
    su = material.ultimate_strength_mpa
    if su is None:
        raise DesignError("material.ultimate_strength_mpa", "is required by wgcad rating (the fatigue check)")
    assumed = []
    sy = material.yield_strength_mpa
    if sy is None:
        sy = 0.9 * su
        assumed.append("yield strength 0.9 S_u")
    if sy > su:
        raise DesignError("material.yield_strength_mpa", f"{sy:g} MPa must not exceed ultimate_strength_mpa {su:g} MPa")
    se = material.endurance_limit_mpa
    if se is None:
        se = min(0.5 * su, 700.0)
        assumed.append("S_e' = 0.5 S_u, at most 700 MPa")
    if se >= su:
        raise DesignError("material.endurance_limit_mpa", f"{se:g} MPa must be below ultimate_strength_mpa {su:g} MPa")
    a, b = SURFACE_FACTORS[material.surface_finish]
    z = NormalDist().inv_cdf(material.reliability)
    return Strength(
        ultimate=float(su),
        yield_=float(sy),
        endurance_specimen=float(se),
        k_a=float(min(1.0, a * su**b)),
        k_b=_size_factor(section_h, section_b),
        k_e=float(min(1.0, 1.0 - 0.08 * z)),
        surface_finish=material.surface_finish,
        reliability=float(material.reliability),
        assumed=tuple(assumed),
    )


def goodman_safety(amplitude: float, mean: float, shear_mean: float, st: Strength) -> float:
    """Goodman's safety factor of a cycle (MPa): the alternating part over ``S_e`` plus the von Mises mean
    ``sqrt(mean^2 + 3 shear_mean^2)`` over ``S_u`` (a compressive normal mean is not credited: it counts as 0)."""
    m = sqrt(max(mean, 0.0) ** 2 + 3.0 * shear_mean**2)
    u = amplitude / st.endurance + m / st.ultimate
    return float("inf") if u <= 0 else 1.0 / u
