"""The kinematics' own input checks (wgcad.kinematics): each bad value refused naming its key and the rule, each
bound where the docs put it. Written against the survivors of ``benchmarks/mutation.py --only kinematics``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wgcad.errors import DesignError
from wgcad.kinematics import flex_rotation, gear_ratios, ring_generator_velocities
from wgcad.laws import ExternalRing

LAW = ExternalRing(w0=0.9, r_m=135.0, beta=np.radians(40.0))


def _refused(call, field: str, message: str) -> None:
    with pytest.raises(DesignError) as e:
        call()
    assert e.value.field == field and str(e.value) == f"{field}: {message}"


@pytest.mark.parametrize(
    "z_flex, z_rigid, field, message",
    [
        (0, 202, "drive.z_flex", "must be a positive integer tooth count, got 0"),
        (200, -2, "drive.z_rigid", "must be a positive integer tooth count, got -2"),
        (200.0, 202, "drive.z_flex", "must be a positive integer tooth count, got 200.0"),
        (True, 202, "drive.z_flex", "must be a positive integer tooth count, got True"),
        (200, 200, "drive.z_rigid", "must differ from the flexspline's 200 teeth"),
    ],
)
def test_tooth_counts_are_refused_naming_the_key_and_rule(z_flex, z_rigid, field, message):
    _refused(lambda: gear_ratios(z_flex, z_rigid), field, message)


def test_one_tooth_is_a_tooth_count():
    """The bound is >= 1: a one-tooth gear against three (a toy, but a count) has u_hg = z_g / (z_g - z_b) = -0.5."""
    assert gear_ratios(1, 3)["u_hg"] == pytest.approx(1 / (1 - 3), rel=1e-15)


def test_flex_rotation_of_integer_angles_is_the_float_ratio():
    """Generator angles given as integers turn the flexspline by phi_h / u_hg in floating point (not floor
    division): 1 rad of the generator on 200/202 turns it by -0.01 rad."""
    out = flex_rotation([0, 1, 2], 200, 202)
    np.testing.assert_allclose(out, [0.0, -0.01, -0.02], rtol=1e-14, atol=0)


@pytest.mark.parametrize(
    "omega_h, h_c, a_w, field, message",
    [
        (math.inf, 0.9, 0.9, "omega_h", "must be finite, got inf"),
        (210.0, math.nan, 0.9, "h_c", "must be finite, got nan"),
        (210.0, 0.9, -math.inf, "a_w", "must be finite, got -inf"),
        (210.0, -0.1, 0.9, "h_c", "wall thickness must be >= 0 mm, got -0.1"),
        (210.0, 0.9, -0.2, "a_w", "washer eccentricity must be >= 0 mm, got -0.2"),
    ],
)
def test_ring_generator_refuses_each_bad_value_naming_it(omega_h, h_c, a_w, field, message):
    _refused(lambda: ring_generator_velocities(LAW, [0.0], omega_h, h_c, a_w), field, message)


def test_ring_generator_admits_zero_wall_and_zero_eccentricity():
    """h_c = 0 (K on the neutral line) and a_w = 0 (no crank) are the bounds, not outside them: the washers' speed
    V_d = omega_h a_w is then 0, and the fields are read-only float arrays."""
    vel = ring_generator_velocities(LAW, [0, 1], 210, 0, 0)
    np.testing.assert_array_equal(vel.V_d, [0.0, 0.0])
    assert vel.V_d.dtype == np.float64 and not vel.V_d.flags.writeable
