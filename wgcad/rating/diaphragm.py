"""Bending of the cup's diaphragm: an annular plate clamped at its hub whose outer edge follows the coned cup wall (docs/models.md 10.1).

Coning makes the cup wall pivot about the diaphragm (docs/models.md 3.1): at
the diaphragm its radial displacement vanishes and its slope is
``W'(phi) = -w_c(phi) / (l - z_h)`` (``w_c`` the radial displacement of the
generator's centre section). An inextensible wall with no shear then moves
the joint axially by ``u_z = -r W'_n / n^2`` for each harmonic ``n`` of
``W'``, and a rigid joint turns the plate's edge by ``-W'``. For each
harmonic the plate's deflection is ``f(r) cos(n phi)`` with
``f = A r^n + B r^(n+2) + C r^-n + D r^(2-n)`` (the biharmonic's solutions),
clamped at the hub (``f = f' = 0``) and given ``f, f'`` at the wall; the
radial bending stress is ``6 M_r / h^2`` with
``M_r = -D (f'' + nu (f'/r - n^2 f / r^2))``. Harmonics 0 and 1 (breathing
and translation of the rim) are left to the supports.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Diaphragm", "edge_stress_factors", "diaphragm_stress"]

_SAMPLES = 720
_HARMONICS = 40


@dataclass(frozen=True, slots=True)
class Diaphragm:
    """The plate: clamped at ``r_i``, joined to the wall at ``r_o`` (mm), ``h`` thick; the wall pivots ``arm`` (mm,
    ``l - z_h``) from the generator's centre section."""

    r_i: float
    r_o: float
    h: float
    arm: float


def _basis(n: int, r: float) -> np.ndarray:
    """``(3, 4)``: the four solutions, their first and second derivatives at ``r``."""
    p = np.array([n, n + 2, -n, 2 - n], dtype=float)
    return np.array([r**p, p * r ** (p - 1), p * (p - 1) * r ** (p - 2)])


def edge_stress_factors(n: int, plate: Diaphragm, E: float, nu: float) -> tuple[float, float]:
    """Radial bending stress at the hub and at the wall (MPa, top surface) per unit wall slope ``W'_n`` of harmonic
    ``n >= 2``."""
    bi, bo = _basis(n, plate.r_i), _basis(n, plate.r_o)
    A = np.array([bi[0], bi[1], bo[0], bo[1]])
    rhs = np.array([0.0, 0.0, -plate.r_o / n**2, -1.0])
    c = np.linalg.solve(A, rhs)
    D = E * plate.h**3 / (12.0 * (1.0 - nu**2))
    out = []
    for r, b in ((plate.r_i, bi), (plate.r_o, bo)):
        f, f1, f2 = b @ c
        m = -D * (f2 + nu * (f1 / r - n * n * f / r**2))
        out.append(6.0 * m / plate.h**2)
    return float(out[0]), float(out[1])


def diaphragm_stress(centre_law, plate: Diaphragm, E: float, nu: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(psi, sigma_hub, sigma_wall)``: the plate's radial bending stress at the hub and at the wall around the
    rim, MPa, for the neutral line ``centre_law`` of the generator's centre section."""
    psi = np.linspace(0.0, 2.0 * np.pi, _SAMPLES, endpoint=False)
    slope = -centre_law.state(psi).w / plate.arm
    c = np.fft.rfft(slope)
    hub, wall = np.zeros_like(c), np.zeros_like(c)
    for n in range(2, min(_HARMONICS, len(c) - 1) + 1):
        ki, ko = edge_stress_factors(n, plate, E, nu)
        hub[n], wall[n] = ki * c[n], ko * c[n]
    return psi, np.fft.irfft(hub, _SAMPLES), np.fft.irfft(wall, _SAMPLES)


#: the sizing's steps, mm: the workshop's thickness step (as [parts]' derived sizes) and the step the bolt circle's
#: outer limit moves inward by
H_STEP = 0.05
R_STEP = 0.5


@dataclass(frozen=True, slots=True)
class PlateCheck:
    """Goodman's safety of a plate at its hub and at the wall (the smaller binds), under ``torque_nm``."""

    plate: Diaphragm
    hub: float
    wall: float
    torque_nm: float

    @property
    def safety(self) -> float:
        return min(self.hub, self.wall)


def plate_safety(centre_law, plate: Diaphragm, E: float, nu: float, torque_nm: float, st) -> PlateCheck:
    """Goodman's safety (:func:`wgcad.rating.fatigue.goodman_safety`) of ``plate`` at its hub and wall: the bending
    cycle of :func:`diaphragm_stress` for ``centre_law`` with the torque's shear ``T / (2 pi r^2 h)``, the figures the
    datasheet's diaphragm rows give."""
    from .fatigue import goodman_safety
    from .rim import RimCycle, torque_shear

    psi, hub, wall = diaphragm_stress(centre_law, plate, E, nu)
    out = []
    for r, sigma in ((plate.r_i, hub), (plate.r_o, wall)):
        c = RimCycle(psi, sigma)
        out.append(goodman_safety(c.amplitude, c.mean, torque_shear(torque_nm, r, plate.h), st))
    return PlateCheck(plate, out[0], out[1], float(torque_nm))
