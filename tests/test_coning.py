"""Tests of wgcad.laws.coning: linear amplitude along a cup flexspline (docs/models.md 3.1)."""

import math

import numpy as np
import pytest

from wgcad.errors import DesignError
from wgcad.laws import coned_w0, make_law

L, Z_H, W0 = 160.0, 12.0, 0.88  # D1: shell length 160 mm, W0 = 1.1 m


def test_values_at_generator_diaphragm_and_open_end():
    out = coned_w0(W0, [Z_H, L, 0.0], length=L, z_h=Z_H)
    assert out[0] == W0  # (l - z_h)/(l - z_h) is exactly 1
    assert out[1] == 0.0
    assert out[2] == pytest.approx(W0 * L / (L - Z_H), rel=1e-15)


def test_linear_in_z_and_shape_preserved():
    z = np.linspace(0.0, L, 24).reshape(4, 6)
    out = coned_w0(W0, z, length=L, z_h=Z_H)
    assert out.shape == (4, 6) and not out.flags.writeable
    flat = out.ravel()
    # second differences of a linear function vanish up to rounding of O(W0) values
    np.testing.assert_allclose(np.diff(flat, 2), 0.0, atol=1e-14)
    slope = np.diff(flat) / np.diff(z.ravel())
    np.testing.assert_allclose(slope, -W0 / (L - Z_H), rtol=1e-12)


def test_scalar_z_gives_0d_array():
    out = coned_w0(W0, 30.0, length=L, z_h=Z_H)
    assert out.shape == () and float(out) == pytest.approx(W0 * (L - 30.0) / (L - Z_H))


def test_feeds_a_law_cross_section_by_cross_section():
    law = make_law("four_force", w0=W0, r_m=80.0, beta=math.radians(35))
    z = np.array([0.0, 15.0, 30.0])
    for zk, wk in zip(z, coned_w0(W0, z, length=L, z_h=Z_H)):
        assert law.with_w0(wk).state(0.0).w == pytest.approx(wk, rel=1e-14)


@pytest.mark.parametrize(
    "w0,z,length,z_h,field",
    [
        (W0, 0.0, 10.0, 10.0, "generator.cone_length"),  # length == z_h
        (W0, 0.0, 5.0, 10.0, "generator.cone_length"),  # length < z_h
        (W0, 0.0, -1.0, 0.0, "generator.cone_length"),
        (W0, 0.0, L, -1.0, "generator.generator_z"),
        (W0, 0.0, float("inf"), Z_H, "generator.cone_length"),
        (0.0, 0.0, L, Z_H, "generator.w0_coef"),
        (-W0, 0.0, L, Z_H, "generator.w0_coef"),
        (W0, [0.0, L + 1.0], L, Z_H, "generator.cone_length"),  # beyond the diaphragm
        (W0, [-1.0, 0.0], L, Z_H, "generator.cone_length"),  # beyond the open end
        (W0, [float("nan")], L, Z_H, "generator.cone_length"),
    ],
)
def test_rejects(w0, z, length, z_h, field):
    with pytest.raises(DesignError) as exc:
        coned_w0(w0, z, length=length, z_h=z_h)
    assert exc.value.field == field
