"""Bending of the flexspline rim and cup wall from the curvature change of the neutral line, and the torque's shear (docs/models.md 10.1).

The neutral line does not stretch (docs/models.md 3.1), so its curvature
changes by ``dkappa = dtheta/ds = dtheta/dphi / r_m`` (``theta`` the
cross-section's rotation, which every law and the loaded state give in closed
form). A surface at distance ``y`` from the neutral line then carries
``sigma = E y dkappa`` (thin ring, as the elastic model's ``E I``): for
``w = W0 cos 2phi`` the outer fibre sees ``1.5 E t W0 / r^2`` on the major axis.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

__all__ = ["curvature_change", "RimCycle", "rim_cycle", "torque_shear", "sampled_curvature_change"]


def curvature_change(law, phi) -> np.ndarray:
    """Change of the neutral line's curvature at the material angles ``phi`` (rad), 1/mm; positive: more curved.

    ``dtheta/dphi / r_m`` from the law's own state (closed form for every analytic law and the loaded state).
    """
    st = law.state(np.asarray(phi, dtype=float))
    return st.dtheta / law.r_m


def sampled_curvature_change(law, phi, exact: bool = False) -> np.ndarray:
    """The same figure from the sampled neutral line alone (a second method: no ``theta``), 1/mm.

    ``exact=False``: the linearised curvature change ``-(w'' + w) / r_m^2`` of
    the ring, ``w''`` by central differences of the sampled ``w``.
    ``exact=True``: the curvature of the sampled curve ``R(phi) = (r_m + w)
    e_r + v e_t`` minus ``1/r_m``, which departs from the linear figure by
    ``O(W0/r_m)`` of it. ``phi`` uniformly spaced over a whole turn (the ends wrap).
    """
    phi = np.asarray(phi, dtype=float)
    st = law.state(phi)
    h = phi[1] - phi[0]

    def d1(a):
        return (np.roll(a, -1) - np.roll(a, 1)) / (2 * h)

    def d2(a):
        return (np.roll(a, -1) - 2 * a + np.roll(a, 1)) / h**2

    if not exact:
        return -(d2(st.w) + st.w) / law.r_m**2
    r = law.r_m + st.w
    c, s = np.cos(phi), np.sin(phi)
    x = r * c - st.v * s
    y = r * s + st.v * c
    kappa = (d1(x) * d2(y) - d1(y) * d2(x)) / (d1(x) ** 2 + d1(y) ** 2) ** 1.5
    return kappa - 1.0 / law.r_m


@dataclass(frozen=True, slots=True)
class RimCycle:
    """The bending stress one fibre of a section sees over a turn of the wave generator, MPa.

    The rim's shape turns with the generator (quasi-static), so a fibre at a
    fixed place on the rim sees the stress of every angle ``psi`` of the
    generator frame in one turn: ``sigma(psi)`` is its whole cycle.

    Attributes
    ----------
    psi : (n,) float
        Angles from the generator's major axis, rad.
    sigma : (n,) float
        Stress at the surface at ``psi``, MPa (tension positive).
    """

    psi: np.ndarray
    sigma: np.ndarray

    @property
    def amplitude(self) -> float:
        return 0.5 * float(self.sigma.max() - self.sigma.min())

    @property
    def mean(self) -> float:
        return 0.5 * float(self.sigma.max() + self.sigma.min())

    @property
    def peak_at(self) -> float:
        """Angle of the largest tension, rad; of tensions equal to a 1e-9 part of the cycle's range (the waves of a
        symmetric drive) the first, so rounding does not choose between them."""
        s = self.sigma
        tie = 1e-9 * max(float(s.max() - s.min()), float(np.abs(s).max()), 1e-300)
        return float(self.psi[int(np.argmax(s >= s.max() - tie))])


def rim_cycle(law, E: float, y: float, psi) -> RimCycle:
    """Surface stress ``E y dkappa(psi)`` (MPa) at signed distance ``y`` (mm, outward positive) from the neutral line."""
    psi = np.asarray(psi, dtype=float)
    return RimCycle(psi, E * y * curvature_change(law, psi))


def torque_shear(torque_nm: float, radius: float, thickness: float) -> float:
    """Shear stress of a thin tube of ``radius`` and wall ``thickness`` (mm) carrying ``torque_nm``, MPa."""
    return 1e3 * abs(torque_nm) / (2.0 * pi * radius**2 * thickness)
