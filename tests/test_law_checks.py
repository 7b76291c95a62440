"""The laws' own input checks: each bad value is refused naming the design key and the rule, each bound is where
the docs put it, and a law's stored figures are plain floats whatever number type built it.

The schema refuses most bad designs before a law is built, so these checks are what a library caller (and a
design the schema lets through) meets. Written against the survivors of ``benchmarks/mutation.py --only laws``:
messages replaced by None, field names changed, ``<`` turned into ``<=`` at a bound.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wgcad.errors import DesignError
from wgcad.laws import Disc, Harmonic, RimState, coned_w0, make_law

R_M = 50.0


def _refused(call, field: str, *fragments: str) -> None:
    with pytest.raises(DesignError) as e:
        call()
    assert e.value.field == field
    msg = str(e.value)
    assert msg.startswith(f"{field}: ")
    for f in fragments:
        assert f in msg, (f, msg)


@pytest.mark.parametrize(
    "kwargs, field, fragments",
    [
        ({"w0": 1.0, "r_m": 0.0}, "flexspline.rim_thickness", ("neutral-line radius r_m must be > 0 mm", "got 0")),
        ({"w0": 1.0, "r_m": -3.0}, "flexspline.rim_thickness", ("r_m must be > 0 mm", "got -3")),
        ({"w0": 1.0, "r_m": "50"}, "flexspline.rim_thickness", ("neutral-line radius r_m must be a real number",)),
        ({"w0": 1.0, "r_m": math.inf}, "flexspline.rim_thickness", ("neutral-line radius r_m must be finite",)),
        ({"w0": 0.0, "r_m": R_M}, "generator.w0_coef", ("W0 = w0_coef * module must be > 0 mm", "got 0 mm")),
        ({"w0": "1", "r_m": R_M}, "generator.w0_coef", ("W0 = w0_coef * module must be a real number",)),
        ({"w0": True, "r_m": R_M}, "generator.w0_coef", ("W0 = w0_coef * module must be a real number", "True")),
        ({"w0": math.nan, "r_m": R_M}, "generator.w0_coef", ("W0 = w0_coef * module must be finite",)),
        ({"w0": 12.5, "r_m": R_M}, "generator.w0_coef", ("must be < r_m/4 = 12.5 mm", "(docs/models.md 3.1)")),
        ({"w0": 1.0, "r_m": R_M, "n_waves": 0}, "drive.waves", ("must be an integer >= 1", "got 0")),
        ({"w0": 1.0, "r_m": R_M, "n_waves": 2.0}, "drive.waves", ("must be an integer >= 1", "got 2.0")),
        ({"w0": 1.0, "r_m": R_M, "n_waves": True}, "drive.waves", ("must be an integer >= 1",)),
    ],
)
def test_harmonic_refuses_each_bad_value_naming_its_key_and_rule(kwargs, field, fragments):
    _refused(lambda: Harmonic(**kwargs), field, *fragments)


def test_the_bounds_themselves_are_admitted():
    """One wave, a rim radius under 1 mm and W0 just under r_m / 4 are valid (the bounds are strict where the docs
    say ``> 0`` and ``>= 1``)."""
    assert Harmonic(w0=0.1, r_m=0.5, n_waves=1).state(0.0).w == pytest.approx(0.1, abs=1e-15)
    assert Harmonic(w0=12.499, r_m=R_M).w0 == 12.499


def test_stored_figures_are_plain_numbers_whatever_built_them():
    """A law built from numpy scalars or ints stores Python floats and an int wave count (what its JSON and its
    comparisons see)."""
    law = Harmonic(w0=np.float32(1.5), r_m=50, n_waves=np.int64(2))
    assert type(law.w0) is float and law.w0 == 1.5
    assert type(law.r_m) is float and law.r_m == 50.0
    assert type(law.n_waves) is int and law.n_waves == 2


@pytest.mark.parametrize(
    "kwargs, field, fragments",
    [
        ({"beta": None}, "generator.beta_deg", ("is required by law 'disc'",)),
        ({"beta": "0.5"}, "generator.beta_deg", ("beta must be a real number",)),
        ({"beta": 0.0}, "generator.beta_deg", ("must be in (0, 90) degrees", "got 0")),
        ({"beta": math.pi / 2}, "generator.beta_deg", ("must be in (0, 90) degrees", "got 90")),
        ({"beta": 0.5, "n_waves": 3}, "drive.waves", ("law 'disc' has two waves, got 3", "only 'harmonic'")),
        ({"beta": 0.5, "n_waves": 2.0}, "drive.waves", ("law 'disc' has two waves, got 2.0",)),
    ],
)
def test_two_wave_laws_refuse_each_bad_value_naming_its_key_and_rule(kwargs, field, fragments):
    _refused(lambda: make_law("disc", w0=0.8, r_m=R_M, **kwargs), field, *fragments)


def test_a_disc_law_is_odd_in_its_odd_fields_on_both_sides_of_the_axis():
    """v, dw and theta are odd about the major axis: the law's mirror at -phi, to the last bit."""
    law = Disc(w0=0.72, r_m=60.0, beta=np.radians(30.0))
    phi = np.linspace(1e-6, 1.5, 9)
    a, b = law.state(phi), law.state(-phi)
    for f in ("v", "dw", "theta"):
        np.testing.assert_array_equal(getattr(b, f), -getattr(a, f))
    for f in ("w", "d2w", "dv", "dtheta"):
        np.testing.assert_array_equal(getattr(b, f), getattr(a, f))


@pytest.mark.parametrize(
    "kwargs, field, fragments",
    [
        ({"w0": 0.0}, "generator.w0_coef", ("W0 = w0_coef * module must be > 0 mm",)),
        ({"w0": "1"}, "generator.w0_coef", ("W0 = w0_coef * module must be a real number",)),
        ({"length": 0.0}, "generator.cone_length", ("must be > 0 mm", "got 0")),
        ({"length": "160"}, "generator.cone_length", ("length must be a real number",)),
        ({"z_h": -1.0}, "generator.generator_z", ("must be >= 0 mm (z = 0 is the open end)", "got -1")),
        ({"z_h": "10"}, "generator.generator_z", ("z_h must be a real number",)),
        ({"z_h": 160.0}, "generator.cone_length", ("must exceed the generator position z_h = 160 mm",)),
        (
            {"z": [0.0, 170.0]},
            "generator.cone_length",
            ("cross-sections must lie on the flexspline", "got z in [0, 170]"),
        ),
    ],
)
def test_coning_refuses_each_bad_value_naming_its_key_and_rule(kwargs, field, fragments):
    args = {"w0": 1.0, "z": [0.0, 10.0], "length": 160.0, "z_h": 10.0, **kwargs}
    _refused(lambda: coned_w0(args["w0"], args["z"], length=args["length"], z_h=args["z_h"]), field, *fragments)


def test_coning_admits_its_bounds_and_returns_read_only_floats():
    """z_h = 0 (the generator at the open end) and a cone under 1 mm long are valid; W0(z) is the closed form."""
    out = coned_w0(1.0, [0, 1], length=2, z_h=0)
    assert out.dtype == np.float64 and not out.flags.writeable
    np.testing.assert_allclose(out, [1.0, 0.5], rtol=0, atol=1e-15)
    np.testing.assert_allclose(coned_w0(2.0, [0.25], length=0.75, z_h=0.5), [2.0 * 0.5 / 0.25], rtol=1e-15)


def test_rim_state_keeps_float_copies_and_names_a_wrong_shape():
    phi = [0, 1, 2]
    s = RimState(phi, w=[1, 2, 3], dw=phi, d2w=phi, v=phi, dv=phi, theta=phi, dtheta=phi)
    assert s.w.dtype == np.float64 and s.phi.dtype == np.float64 and not s.w.flags.writeable
    with pytest.raises(ValueError, match=r"RimState\.w has shape \(2,\), phi has \(3,\)"):
        RimState(phi, w=[1, 2], dw=phi, d2w=phi, v=phi, dv=phi, theta=phi, dtheta=phi)
