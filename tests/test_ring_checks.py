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
