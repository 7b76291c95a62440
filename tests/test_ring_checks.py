"""The ring's own input checks and its two ways of answering a load (wgcad.elastic.ring).

Written against the survivors of ``benchmarks/mutation.py --only ring``: ``Ring.displacements`` (what the loaded
law evaluates) had no test of its own, and the radius and stiffness checks' keys, messages and bounds none either.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wgcad.elastic.ring import Ring
from wgcad.errors import DesignError

R_M, EI = 80.78, 8.94e6


def test_displacements_are_the_fields_w_v_theta():
    """``displacements`` (the loaded law's call) equals ``w, v, theta`` of ``field`` (the derivation with all the
    derivatives, a second code path over the same kernels) for random loads at random angles, to 1e-12 of the
    largest value; and a couple, a radial and a tangential force each move the rim (no load type dropped)."""
    ring = Ring(R_M, EI)
    rng = np.random.default_rng(7)
    phi = rng.uniform(-np.pi, np.pi, 40)
    psi = rng.uniform(-np.pi, np.pi, 6)
    loads = rng.normal(size=(6, 3)) * [1000.0, 500.0, 2e4]
    w, v, th = ring.displacements(phi, psi, loads)
    f = ring.field(phi, psi, loads)
    for got, want in ((w, f["w"]), (v, f["v"]), (th, f["theta"])):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    for j in range(3):
        one = np.zeros((1, 3))
        one[0, j] = 1.0
        w1, v1, t1 = ring.displacements(phi, [0.3], one)
        assert np.abs(w1).max() > 0 and np.abs(v1).max() > 0 and np.abs(t1).max() > 0


def test_two_opposite_forces_change_the_diameter_by_the_closed_form_in_displacements_too():
    """docs/models.md 4.1: two opposite radial forces P change the diameter along them by (pi/4 - 2/pi) P r^3 / EI
    (outward forces lengthen it), here through ``displacements``."""
    ring, P = Ring(R_M, EI), 1000.0
    w, _, _ = ring.displacements([0.0, np.pi], [0.0, np.pi], [[P, 0, 0], [P, 0, 0]])
    assert w[0] + w[1] == pytest.approx((np.pi / 4 - 2 / np.pi) * P * R_M**3 / EI, rel=1e-12)


@pytest.mark.parametrize(
    "r, ei, field, fragment",
    [
        (0.0, EI, "flexspline.rim_thickness", "ring radius must be > 0 mm, got 0"),
        (-5.0, EI, "flexspline.rim_thickness", "ring radius must be > 0 mm, got -5"),
        (math.inf, EI, "flexspline.rim_thickness", "ring radius must be > 0 mm, got inf"),
        (R_M, 0.0, "material.youngs_modulus_gpa", "ring bending stiffness must be > 0, got 0 N mm^2"),
        (R_M, -1.0, "material.youngs_modulus_gpa", "ring bending stiffness must be > 0, got -1 N mm^2"),
        (R_M, math.inf, "material.youngs_modulus_gpa", "ring bending stiffness must be > 0, got inf N mm^2"),
    ],
)
def test_a_ring_refuses_a_bad_radius_or_stiffness_naming_the_key(r, ei, field, fragment):
    with pytest.raises(DesignError) as e:
        Ring(r, ei)
    assert e.value.field == field and str(e.value) == f"{field}: {fragment}"


def test_a_small_ring_is_a_ring():
    """The bounds are > 0, not > 1: a 0.5 mm ring of stiffness 0.5 N mm^2 answers, and as r^3 / EI says."""
    small, big = Ring(0.5, 0.5), Ring(1.0, 1.0)
    ws = small.displacements([0.0], [0.0], [[1.0, 0, 0]])[0][0]
    wb = big.displacements([0.0], [0.0], [[1.0, 0, 0]])[0][0]
    assert ws == pytest.approx(wb * 0.125 / 0.5, rel=1e-12)


# --- the tables the fast field is summed with (docs/models.md 4.1), checked where they are built --------------------
# They are built once when the module loads; the checks below build them again and hold each to what it stands for,
# so a wrong entry is seen here (and the mutation run, which switches a mutant only inside a call, reaches them).


def _u_terms(a, b):
    """The point's and the load's features and the step ``H = [a < b]`` the split is written in."""
    from wgcad.elastic.ring import _features

    H = (a < b).astype(float)
    return _features(a - math.pi, np.cos(a), np.sin(a)), _features(b, np.cos(b), np.sin(b)), H


def test_the_split_of_each_basis_into_point_and_load_factors_is_exact():
    """``u^k T(u)`` of ``u = mod(a - b, 2 pi) - pi`` equals the sum of its monomials ``c f(a) g(b) H^h`` (from
    ``_split_terms``) and of the ``split`` table's rows, for angles all over the turn, to rounding."""
    from wgcad.elastic.ring import _basis, _field_tables, _split_terms

    rng = np.random.default_rng(11)
    a = rng.uniform(0, 2 * math.pi, 400)
    b = rng.uniform(0, 2 * math.pi, 400)
    u = np.mod(a - b, 2 * math.pi) - math.pi
    want = _basis(u)  # (N, 9)
    fa, fb, H = _u_terms(a, b)
    terms = _split_terms()
    assert sorted(terms) == [(k, t) for k in range(3) for t in range(3)]
    for (k, t), mono in terms.items():
        got = sum(c * fa[:, ia] * fb[:, ib] * (H if h else 1.0) for c, ia, ib, h in mono)
        np.testing.assert_allclose(got, want[:, 3 * k + t], rtol=0, atol=1e-12)
    for n in (3, 4):
        _, split = _field_tables(n)
        split = split.reshape(18, 9, 9)
        for bi in range(9):
            got = sum(
                split[x, f, bi] * fa[:, x // 2] * fb[:, f] * (H if x % 2 else 1.0)
                for x in range(18)
                for f in range(9)
                if split[x, f, bi]
            )
            np.testing.assert_allclose(got, want[:, bi], rtol=0, atol=1e-12)


def test_the_coefficient_table_is_each_load_types_kernel_in_the_bases():
    """``coef[i, type]`` in the bases equals the closed-form kernel the field needs: ``C^(i+1)`` for a radial load,
    ``C^(i)`` for a tangential one, ``E^(i)`` for a couple (``Ring._vfields`` before its scale factors)."""
    from wgcad.elastic.ring import _basis, _field_tables, ring_kernels

    x = np.linspace(0.01, 2 * math.pi - 0.01, 77)
    B = _basis(np.mod(x, 2 * math.pi) - math.pi)
    C, E = ring_kernels(x, 3)
    for n in (3, 4):
        coef, _ = _field_tables(n)
        assert coef.shape == (n, 3, 9)
        for i in range(n):
            for typ, want in ((0, C[i + 1]), (1, C[i]), (2, E[i])):
                np.testing.assert_allclose(B @ coef[i, typ], want, rtol=0, atol=1e-12 * max(1.0, np.abs(want).max()))


def test_the_derivative_tables_are_derivatives():
    """``_derivs`` of a closed form, evaluated, equals the finite differences of the order below (h = 1e-5, error
    ~1e-9 against values of order 1), and ``C`` built by ``_simplify(A - P + F)`` equals its Fourier series."""
    from wgcad.elastic.ring import _A, _F, _P, _derivs, _eval, _neg, _simplify, series_kernels

    u = np.linspace(-3.0, 3.0, 61)
    h = 1e-5

    def ev(terms, uu):
        return _eval(terms, uu, [np.ones_like(uu), uu, uu * uu], np.cos(uu), np.sin(uu))

    C = _simplify(_A + _neg(_P) + _F)
    E = _simplify(_P + _neg(_F))
    x = u + math.pi
    Cs, Es = series_kernels(x, 4000)
    np.testing.assert_allclose(ev(C, u), Cs, rtol=0, atol=1e-10)
    np.testing.assert_allclose(ev(E, u), Es, rtol=0, atol=1e-6)  # the series' tail: sum 1/n^4 beyond 4000
    for terms, n in ((C, 4), (E, 3)):
        ds = _derivs(terms, n)
        assert len(ds) == n + 1 and ds[0] == terms
        for k in range(1, n + 1):
            fd = (ev(ds[k - 1], u + h) - ev(ds[k - 1], u - h)) / (2 * h)
            np.testing.assert_allclose(ev(ds[k], u), fd, rtol=0, atol=1e-8)


def test_ring_kernels_by_default_give_what_the_displacements_need():
    """``ring_kernels(x)``: ``C, C'`` and ``E`` (order 0), the same values as asked for explicitly."""
    from wgcad.elastic.ring import ring_kernels

    x = np.linspace(0.1, 6.0, 9)
    C, E = ring_kernels(x)
    assert len(C) == 2 and len(E) == 1
    C1, E1 = ring_kernels(x, 0)
    np.testing.assert_array_equal(C[1], C1[1])
    np.testing.assert_array_equal(E[0], E1[0])


def _direct_dtheta(ring, phi, psi, loads):
    x = np.asarray(phi, float)[:, None] - np.asarray(psi, float)[None, :]
    d = [np.zeros(len(phi)) for _ in range(4)]
    for j, vf in enumerate(ring._vfields(x, 1)):
        for i in range(4):
            d[i] += vf[i] @ loads[:, j]
    return (d[1] + d[3]) / ring.r


def test_a_point_on_a_couple_a_turn_away_takes_the_kernel_matrixs_side():
    """Points whose ``mod(phi - psi)`` falls on the other side of a couple than ``mod(phi) < mod(psi)`` says (found
    by search: a point just below 0 against a load at 2 pi, and a point a few turns from its load), alone and
    after a point that sits exactly on its load (its branch agrees): ``dtheta`` jumps there, and the fast field
    takes the kernel matrix's side."""
    ring = Ring(R_M, EI)
    cases = [
        # a point a hair below 0 (mod: 2 pi) against a couple at 2 pi (mod: 0): the wrap-around window
        (np.array([-1.3077531969011477e-18]), np.array([6.283185307179586])),
        # the same after a point exactly on its own load (same branch, nothing to correct) and an ordinary one
        (np.array([0.7, 0.3, -7.058554945166199e-17]), np.array([0.7, 12.566370614359172])),
        # a point four turns from its load, which mod rounds to the other side
        (np.array([25.132741228718338]), np.array([6.283185307179581])),
    ]
    for phi, psi in cases:
        loads = np.zeros((len(psi), 3))
        loads[:, 2] = 1e4  # couples: their dtheta jumps at the load
        got = ring.field(phi, psi, loads)["dtheta"]
        want = _direct_dtheta(ring, phi, psi, loads)
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11 * np.abs(want).max())
