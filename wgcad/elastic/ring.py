"""Compliance of a thin inextensible ring under radial, tangential and couple point loads (docs/models.md 4.1)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from wgcad.errors import DesignError

__all__ = ["Ring", "ring_kernels", "series_kernels"]

# --------------------------------------------------------------------------
# closed forms of the Fourier sums (docs/models.md 4.1)
#
# A displacement field v = sum_{n>=2} (a_n cos n phi + b_n sin n phi) of the
# inextensible ring (v' = -w, theta = (v + v'')/r, docs/models.md 3.1) stores
# U = pi EI n^2 (n^2 - 1)^2 (a_n^2 + b_n^2) / (2 r^3); the n = 0, 1 terms are
# the rigid-body modes and carry no energy. Unit loads at psi (radial,
# tangential, couple) do work on the shapes (n sin, -n cos), (cos, sin) and
# ((1 - n^2)/r)(cos, sin) of (a_n, b_n), which gives the influence sums
#   vv: r^3/(pi EI) S C(x),  C = sum cos(nx)/(n^2 (n^2-1)^2)
#   and every other pair as a derivative of C or of E = sum cos(nx)/(n^2(n^2-1)),
# x = phi - psi. Partial fractions reduce them to three sums with known
# closed forms on 0 <= x <= 2 pi, written in u = x - pi:
#   A = sum_{n>=2} cos(nx)/(n^2-1)^2 = -1/2 + (pi^2/24 + 3/16) cos u - u^2 cos u/8 + u sin u/4
#   P = sum_{n>=2} cos(nx)/(n^2-1)   = 1/2 - cos u/4 - u sin u/2
#   F = sum_{n>=2} cos(nx)/n^2       = u^2/4 - pi^2/12 + cos u
#   C = A - P + F,   E = P - F.
# (A solves A'' + A = -P with no n = 0, 1 terms and A(x) = A(2 pi - x); P
# likewise from P'' + P = 1/2 + cos x; F is the Bernoulli polynomial sum minus
# its n = 1 term. Each is checked against the series in tests/test_elastic_ring.py.)
# Terms are (coefficient, power of u, kind) with kind 0: u^k, 1: u^k cos u, 2: u^k sin u.

_A = [(-0.5, 0, 0), (pi**2 / 24 + 3.0 / 16.0, 0, 1), (-0.125, 2, 1), (0.25, 1, 2)]
_P = [(0.5, 0, 0), (-0.25, 0, 1), (-0.5, 1, 2)]
_F = [(0.25, 2, 0), (-(pi**2) / 12.0, 0, 0), (1.0, 0, 1)]


def _neg(terms):
    return [(-c, k, t) for c, k, t in terms]


def _simplify(terms):
    acc = {}
    for c, k, t in terms:
        acc[(k, t)] = acc.get((k, t), 0.0) + c
    return [(c, k, t) for (k, t), c in sorted(acc.items()) if c != 0.0]


def _deriv(terms):
    out = []
    for c, k, t in terms:
        if k:
            out.append((c * k, k - 1, t))
        if t == 1:  # d cos = -sin
            out.append((-c, k, 2))
        elif t == 2:  # d sin = cos
            out.append((c, k, 1))
    return _simplify(out)


_C = _simplify(_A + _neg(_P) + _F)
_E = _simplify(_P + _neg(_F))


def _derivs(terms, n):
    out = [terms]
    for _ in range(n):
        out.append(_deriv(out[-1]))
    return out


#: derivatives 0..4 of C and 0..3 of E
_CD = _derivs(_C, 4)
_ED = _derivs(_E, 3)


def _eval(terms, u, powers, cu, su):
    out = np.zeros_like(u)
    for c, k, t in terms:
        base = powers[k]
        if t == 1:
            base = base * cu
        elif t == 2:
            base = base * su
        out += c * base
    return out


def ring_kernels(x, order: int = 0):
    """Derivatives of the two basic influence sums ``C`` and ``E`` at angles ``x``.

    Parameters
    ----------
    x : (...) float
        Angle from the load to the observed point, rad (any value; reduced to [0, 2 pi)).
    order : int
        Highest derivative of the displacement kernels needed (0..2 for
        w, v, theta at the point; 3 for their derivatives along the ring).

    Returns
    -------
    C : list of (...) float
        ``C, C', ..., C^(order+1)`` (radial loads need one more derivative).
    E : list of (...) float
        ``E, E', ..., E^(order)``.
    """
    x = np.asarray(x, dtype=float)
    u = np.mod(x, 2.0 * pi) - pi
    powers = [np.ones_like(u), u, u * u]
    cu, su = np.cos(u), np.sin(u)
    C = [_eval(t, u, powers, cu, su) for t in _CD[: order + 2]]
    E = [_eval(t, u, powers, cu, su) for t in _ED[: order + 1]]
    return C, E


def series_kernels(x, n_max: int = 20000):
    """``C`` and ``E`` by their Fourier series truncated at ``n_max`` (a check of the closed forms).

    Returns
    -------
    (C, E) : two (...) float arrays
    """
    x = np.asarray(x, dtype=float)
    n = np.arange(2, n_max + 1, dtype=float)
    c = np.cos(np.multiply.outer(x, n))
    n2 = n * n
    return c @ (1.0 / (n2 * (n2 - 1.0) ** 2)), c @ (1.0 / (n2 * (n2 - 1.0)))


@dataclass(frozen=True, slots=True)
class Ring:
    """A thin inextensible elastic ring: radius ``r`` (mm), bending stiffness ``EI`` (N mm^2).

    Loads are generalized point loads at angles ``psi``: a radial force
    (outward positive, N), a tangential force (counter-clockwise positive, N)
    and a couple (counter-clockwise, N mm). Responses are the neutral line's
    ``w`` (outward), ``v`` (counter-clockwise) and the cross-section rotation
    ``theta`` of docs/models.md 3.1. Only the deformable modes n >= 2 respond: the
    rigid-body modes (n = 0 rotation, n = 1 translation) are left to the
    equilibrium equations (docs/models.md 4.1), so a load set that is not
    self-equilibrated is answered as if balanced by its n = 0, 1 components.
    """

    r: float
    EI: float

    def __post_init__(self):
        if not (np.isfinite(self.r) and self.r > 0):
            raise DesignError("flexspline.rim_thickness", f"ring radius must be > 0 mm, got {self.r:g}")
        if not (np.isfinite(self.EI) and self.EI > 0):
            raise DesignError(
                "material.youngs_modulus_gpa", f"ring bending stiffness must be > 0, got {self.EI:g} N mm^2"
            )

    def _vfields(self, x, order):
        """v-field kernels and their derivatives 0..order+2 along phi, per load type: (3, order+3, ...)."""
        C, E = ring_kernels(x, order + 2)
        s3 = self.r**3 / (pi * self.EI)
        s2 = self.r**2 / (pi * self.EI)
        rad = [s3 * C[i + 1] for i in range(order + 3)]  # v = s3 C'(x)
        tan = [s3 * C[i] for i in range(order + 3)]  # v = s3 C(x)
        cpl = [-s2 * E[i] for i in range(order + 3)]  # v = -s2 E(x)
        return rad, tan, cpl

    def block(self, x):
        """Influence block at angles ``x = phi - psi``: ``(..., 3, 3)`` (rows w, v, theta; columns radial, tangential, couple).

        Symmetric in the Maxwell-Betti sense: ``block(x)[i, j] == block(-x)[j, i]``.
        """
        x = np.asarray(x, dtype=float)
        out = np.empty(x.shape + (3, 3))
        for j, vf in enumerate(self._vfields(x, 0)):
            v, d1, d2 = vf[0], vf[1], vf[2]
            out[..., 0, j] = -d1  # w = -v'
            out[..., 1, j] = v
            out[..., 2, j] = (v + d2) / self.r  # theta = (v + v'')/r
        return out

    def displacements(self, phi, psi, loads):
        """``w, v, theta`` at ``phi`` due to generalized loads at ``psi`` (:meth:`field` without the derivatives), three (K,) arrays."""
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        psi = np.atleast_1d(np.asarray(psi, dtype=float))
        loads = np.asarray(loads, dtype=float).reshape(len(psi), 3)
        x = phi[:, None] - psi[None, :]
        d = [np.zeros(len(phi)) for _ in range(3)]
        for j, vf in enumerate(self._vfields(x, 0)):
            for i in range(3):
                d[i] += vf[i] @ loads[:, j]
        v, v1, v2 = d
        return -v1, v, (v + v2) / self.r

    def field(self, phi, psi, loads):
        """Neutral-line state at ``phi`` due to generalized loads at ``psi``.

        Parameters
        ----------
        phi : (K,) float
        psi : (L,) float
        loads : (L, 3) float
            Radial force, tangential force (N), couple (N mm) at each ``psi``.

        Returns
        -------
        dict of (K,) float: ``w, dw, d2w, v, dv, theta, dtheta`` (mm, rad; derivatives per rad of phi).
        """
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        psi = np.atleast_1d(np.asarray(psi, dtype=float))
        loads = np.asarray(loads, dtype=float).reshape(len(psi), 3)
        x = phi[:, None] - psi[None, :]
        d = [np.zeros(len(phi)) for _ in range(4)]
        for j, vf in enumerate(self._vfields(x, 1)):
            for i in range(4):
                d[i] += vf[i] @ loads[:, j]
        v, v1, v2, v3 = d
        r = self.r
        return {"w": -v1, "dw": -v2, "d2w": -v3, "v": v, "dv": v1, "theta": (v + v2) / r, "dtheta": (v1 + v3) / r}
