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


# --------------------------------------------------------------------------
# the field of many loads at many points in O(K + L) (docs/models.md 4.1)
#
# Every kernel is a sum of u^k T(u), k <= 2, T in {1, cos, sin}, with
# u = mod(phi - psi, 2 pi) - pi. With a = mod(phi, 2 pi), b = mod(psi, 2 pi)
# and H = [a < b], u = (a - pi) - b + 2 pi H exactly in reals, cos u and
# sin u split into products of functions of a and of b, and u, u^2 into
# such products plus H times such products. The sum over the loads of a
# product f(a) g(b) is f(a) times one number; of a product with H, f(a)
# times the sum of g(b) over the loads with b > a: a suffix sum over the
# loads sorted by b. So the field at K points of L loads costs O((K + L) log L)
# instead of the K x L kernel matrix, and equals it to rounding (tested
# against the direct sum, tests/test_elastic_ring.py).

#: features of one angle: {1, y, y^2} x {1, cos, sin}, index 3 k + t
_FEAT = [(k, t) for k in range(3) for t in range(3)]


def _split_terms():
    """``u^k T(u)`` for the nine (k, t) as ``(coef, a feature, b feature, H)`` monomials."""
    two_pi = 2.0 * pi
    # u^k in A = a - pi and B = b: (coef, power of A, power of B, H)
    powers = {
        0: [(1.0, 0, 0, 0)],
        1: [(1.0, 1, 0, 0), (-1.0, 0, 1, 0), (two_pi, 0, 0, 1)],
        2: [
            (1.0, 2, 0, 0),
            (-2.0, 1, 1, 0),
            (1.0, 0, 2, 0),
            (2.0 * two_pi, 1, 0, 1),
            (-2.0 * two_pi, 0, 1, 1),
            (two_pi**2, 0, 0, 1),
        ],
    }
    # T(u) in cos/sin of a and b (cos u = -cos(a - b), sin u = -sin(a - b)): (coef, t of a, t of b)
    trig = {0: [(1.0, 0, 0)], 1: [(-1.0, 1, 1), (-1.0, 2, 2)], 2: [(-1.0, 2, 1), (1.0, 1, 2)]}
    out = {}
    for k, t in _FEAT:
        mono = []
        for cp, pa, pb, h in powers[k]:
            for ct, ta, tb in trig[t]:
                mono.append((cp * ct, 3 * pa + ta, 3 * pb + tb, h))
        out[(k, t)] = mono
    return out


def _field_tables(n_out: int):
    """Constant tables of the field's derivatives ``0..n_out-1`` of ``v``.

    ``coef[i, type, basis]``: the kernel of derivative ``i`` for load type
    (radial, tangential, couple; the ring's scale factors left out) in the
    nine bases ``u^k T(u)``; ``split[x, f, basis]`` with ``x = 2 (a
    feature) + H``: the bases as products of a-features and b-features.
    """
    coef = np.zeros((n_out, 3, 9))
    for i in range(n_out):
        for typ, terms in ((0, _CD[i + 1]), (1, _CD[i]), (2, _ED[i])):
            for c, k, t in terms:
                coef[i, typ, 3 * k + t] += c
    split = np.zeros((18, 9, 9))
    for basis, mono in _split_terms().items():
        bi = 3 * basis[0] + basis[1]
        for c, fa, fb, h in mono:
            split[2 * fa + h, fb, bi] += c
    return coef, split.reshape(18, 81)


_TABLES = {n: _field_tables(n) for n in (3, 4)}


def _features(y, c, s):
    """(N, 9) features {1, y, y^2} x {1, cos, sin} of one angle per row."""
    one = np.ones_like(y)
    return np.stack([one, c, s, y, y * c, y * s, y * y, y * y * c, y * y * s], axis=1)


def _field_sums(phi, psi, weighted, n_out: int):
    """``sum_j kernel_i(phi - psi_j) . weighted[j]`` for derivatives ``i < n_out``: (n_out, K).

    ``weighted`` (L, 3): the loads with the ring's scale factors of each load
    type applied (radial and tangential ``r^3/(pi EI)``, couple ``-r^2/(pi EI)``).
    """
    coef, split = _TABLES[n_out]
    a = np.mod(phi, 2.0 * pi)
    b = np.mod(psi, 2.0 * pi)
    fa = _features(a - pi, np.cos(a), np.sin(a))  # (K, 9)
    fb = _features(b, np.cos(b), np.sin(b))  # (L, 9)
    w = np.einsum("jt,itb->jbi", weighted, coef)  # (L, basis, i)
    prod = (fb[:, :, None, None] * w[:, None, :, :]).reshape(len(b), 81, n_out)
    v = np.matmul(split, prod)  # (L, 18, n_out): [j, 2 feature + H, i]
    dense = v[:, 0::2, :].sum(axis=0)  # (9, n_out)
    order = np.argsort(b, kind="stable")
    tail = np.zeros((len(b) + 1, 9, n_out))
    tail[:-1] = np.cumsum(v[order[::-1], 1::2, :], axis=0)[::-1]  # tail[m]: sum over sorted loads m..L-1
    bs = b[order]
    above = tail[np.searchsorted(bs, a, side="right")]  # (K, 9, n_out): loads with b > a
    out = fa @ dense + np.einsum("kf,kfi->ki", fa, above)
    _same_branch(out, phi, psi, a, b, bs, order, weighted, coef)
    return out.T


#: a point this close (rad) to a load, or to a load a turn away, is checked against the direct sum's branch
_NEAR = 1e-9


def _basis(u):
    """(N, 9) values of ``u^k T(u)`` (index ``3 k + t``) at ``u``."""
    return _features(u, np.cos(u), np.sin(u))


def _same_branch(out, phi, psi, a, b, bs, order, weighted, coef) -> None:
    """Where a point lies on a load (to :data:`_NEAR`), give it the branch ``mod(phi - psi, 2 pi)`` gives it.

    A couple's third derivative of ``v`` (and so ``dtheta``) jumps at its load: exactly there the closed forms take
    the side of ``u = -pi``, and ``mod(phi - psi)`` decides in rounding which side a point on the load is on (the
    kernel matrix's way, which the states' figures were measured with). The sums above decide by
    ``mod(phi) < mod(psi)``; for the few pairs where the two differ, the difference of the two sides is added.
    ``out`` (K, n_out) in place.
    """
    two_pi = 2.0 * pi
    windows = [
        (np.searchsorted(bs, a - _NEAR, side="left"), np.searchsorted(bs, a + _NEAR, side="right")),
        # a load a turn away: a point near 0 and a load near 2 pi, or the other way
        (np.searchsorted(bs, a + two_pi - _NEAR, side="left"), np.full(len(a), len(bs))),
        (np.zeros(len(a), dtype=int), np.searchsorted(bs, a - two_pi + _NEAR, side="right")),
    ]
    for lo, hi in windows:
        n = np.maximum(hi - lo, 0)
        if not n.any():
            continue
        i = np.repeat(np.arange(len(a)), n)
        j = order[np.concatenate([np.arange(l0, l0 + k) for l0, k in zip(lo[n > 0], n[n > 0])])]
        u_direct = np.mod(phi[i] - psi[j], two_pi) - pi
        u_here = (a[i] - pi) - b[j] + two_pi * (a[i] < b[j])
        moved = np.abs(u_direct - u_here) > pi
        if not moved.any():
            continue
        i, j = i[moved], j[moved]
        diff = _basis(u_direct[moved]) - _basis(u_here[moved])  # (P, basis)
        # out[i, k] += sum_type weighted[j, type] sum_basis coef[k, type, basis] diff[basis]
        np.add.at(out, i, np.einsum("pt,ktb,pb->pk", weighted[j], coef, diff))


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

    def _weighted(self, loads):
        """Loads times the scale factor of their type (radial, tangential ``r^3/(pi EI)``, couple ``-r^2/(pi EI)``)."""
        s3 = self.r**3 / (pi * self.EI)
        s2 = self.r**2 / (pi * self.EI)
        return loads * np.array([s3, s3, -s2])

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
        v, v1, v2 = _field_sums(phi, psi, self._weighted(loads), 3)
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
        v, v1, v2, v3 = _field_sums(phi, psi, self._weighted(loads), 4)
        r = self.r
        return {"w": -v1, "dw": -v2, "d2w": -v3, "v": v, "dv": v1, "theta": (v + v2) / r, "dtheta": (v1 + v3) / r}
