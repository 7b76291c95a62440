"""Tests of wgcad.kinematics: gear ratios, flexspline rotation, external ring velocities."""

import math

import numpy as np
import pytest

from wgcad.errors import DesignError
from wgcad.kinematics import RingVelocities, flex_rotation, gear_ratios, ring_generator_velocities
from wgcad.laws import Disc, ExternalRing, Harmonic


def test_ratios_internal_deformation_200_202():
    # docs/models.md 1: u_hg = -z_g/(z_b - z_g), u_hb = z_b/(z_b - z_g)
    assert gear_ratios(200, 202) == {"u_hg": -100.0, "u_hb": 101.0}


def test_ratios_external_deformation_300_298_flip_sign():
    # D3: flexspline 300 internal teeth, rigid gear 298 external teeth
    r = gear_ratios(300, 298)
    assert r == {"u_hg": 150.0, "u_hb": -149.0}
    internal = gear_ratios(200, 202)
    assert np.sign(r["u_hg"]) == -np.sign(internal["u_hg"])
    assert np.sign(r["u_hb"]) == -np.sign(internal["u_hb"])


@pytest.mark.parametrize("z_g,z_b", [(200, 202), (300, 298), (86, 88), (201, 203), (100, 96)])
def test_willis_identity(z_g, z_b):
    # omega_h/omega_g + omega_h/omega_b relation of a differential: u_hb = 1 - u_hg
    r = gear_ratios(z_g, z_b)
    assert r["u_hb"] == pytest.approx(1.0 - r["u_hg"], rel=1e-15)


def test_flex_rotation_directions():
    turn = 2 * math.pi
    # internal: flexspline turns against the generator, 1/100 of its angle
    assert flex_rotation(turn, 200, 202) == pytest.approx(-turn / 100, rel=1e-15)
    # external deformation: same direction as the generator, 1/150
    assert flex_rotation(turn, 300, 298) == pytest.approx(turn / 150, rel=1e-15)
    phi_h = np.linspace(-3, 3, 12).reshape(3, 4)
    out = flex_rotation(phi_h, 200, 202)
    assert out.shape == (3, 4)
    np.testing.assert_allclose(out, phi_h / -100.0, rtol=1e-15)


@pytest.mark.parametrize("z_g,z_b", [(200, 202), (300, 298), (201, 203)])
def test_mesh_period_one_pitch_each(z_g, z_b):
    # docs/models.md 7: after the generator turns 2 pi / z_b relative to the rigid
    # gear, the flexspline has moved exactly one of its pitches relative to
    # the generator (and the rigid gear one of its own).
    phi_h = 2 * math.pi / z_b
    phi_g = flex_rotation(phi_h, z_g, z_b)
    assert phi_g - phi_h == pytest.approx(-2 * math.pi / z_g, rel=1e-13)


@pytest.mark.parametrize(
    "args,field",
    [
        ((200, 200), "drive.z_rigid"),
        ((0, 202), "drive.z_flex"),
        ((200, 202.0), "drive.z_rigid"),
        ((True, 202), "drive.z_flex"),
        ((200, -2), "drive.z_rigid"),
    ],
)
def test_ratio_rejects(args, field):
    with pytest.raises(DesignError) as exc:
        gear_ratios(*args)
    assert exc.value.field == field


# D3 [S3]: m 0.9, 300/298, wall 0.9 mm, beta 40 deg, omega_h 210 1/s;
# centre distance a_w = m (z_g - z_b) / 2 = 0.9 mm; W0 = m.
OMEGA, H_C, A_W = 210.0, 0.9, 0.9
LAW = ExternalRing(w0=0.9, r_m=0.9 * 300 / 2 + 0.45, beta=math.radians(40))


def _fd_time(f, t, h):
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


@pytest.mark.parametrize("law", [LAW, Disc(0.9, 135.9, math.radians(30)), Harmonic(0.9, 135.9)])
def test_velocities_against_time_finite_differences(law):
    phi = np.random.default_rng(2).uniform(-2 * math.pi, 2 * math.pi, 400)
    if hasattr(law, "beta"):  # stencil off the section kinks (w''' jumps)
        red = np.abs(phi - math.pi * np.round(phi / math.pi))
        phi = phi[np.abs(red - law.beta) > 1e-2]
    vel = ring_generator_velocities(law, phi, OMEGA, H_C, A_W)
    t = phi / OMEGA  # docs/models.md 3.5: phi = omega_h t
    h = 1e-3 / OMEGA  # 1e-3 rad of phi

    def field(name):
        def f(tt):
            s = law.state(OMEGA * tt)
            return {
                "w": s.w,
                "v": s.v,
                "theta": s.theta,
                "wK": s.w + H_C / 2,
                "vK": s.v + H_C / 2 * s.theta,
            }[name]

        return f

    # 4th-order stencil in phi: truncation ~1e-12 W0, rounding ~3e-13/1e-3
    # (ring laws, values ~W0); times omega. 1e-9 omega W0 (~2e-7 mm/s) fails on
    # any wrong factor or sign (>= 1e-3 omega W0).
    tol = 1e-9 * OMEGA * law.w0
    for name, got in (("w", vel.V_w), ("v", vel.V_v), ("wK", vel.V_wK), ("vK", vel.V_vK)):
        np.testing.assert_allclose(_fd_time(field(name), t, h), got, rtol=0, atol=tol, err_msg=name)
    np.testing.assert_allclose(_fd_time(field("theta"), t, h), vel.dtheta_dt, rtol=0, atol=tol / law.r_m)


def test_washer_velocities_and_sliding():
    phi = np.linspace(-math.pi, math.pi, 73)
    vel = ring_generator_velocities(LAW, phi, OMEGA, H_C, A_W)
    assert isinstance(vel, RingVelocities)
    np.testing.assert_array_equal(vel.V_d, np.full(phi.shape, OMEGA * A_W))
    np.testing.assert_allclose(np.hypot(vel.V_dw, vel.V_dv), vel.V_d, rtol=1e-15)
    np.testing.assert_allclose(vel.V_dw, A_W * OMEGA * np.sin(phi), rtol=1e-15)
    np.testing.assert_array_equal(vel.V_sl, vel.V_d - vel.V_v)
    # at the major axis the neutral line is at its tangential rest point:
    # v' = -w = +W0 for the external ring, so V_v = omega W0 there
    i0 = np.argmin(np.abs(phi))
    assert vel.V_v[i0] == pytest.approx(OMEGA * LAW.w0, rel=1e-14)
    assert vel.V_w[i0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("shape", [(), (7,), (2, 5)])
def test_velocity_shapes_readonly(shape):
    phi = np.zeros(shape) + 0.3
    vel = ring_generator_velocities(LAW, phi, OMEGA, H_C, A_W)
    for name in RingVelocities.__dataclass_fields__:
        arr = getattr(vel, name)
        assert arr.shape == shape and not arr.flags.writeable and np.all(np.isfinite(arr))


def test_velocities_reverse_with_omega():
    phi = np.linspace(0.1, 3.0, 9)
    a = ring_generator_velocities(LAW, phi, OMEGA, H_C, A_W)
    b = ring_generator_velocities(LAW, phi, -OMEGA, H_C, A_W)
    for name in ("V_w", "V_v", "dtheta_dt", "V_wK", "V_vK", "V_d", "V_dw", "V_dv", "V_sl"):
        np.testing.assert_allclose(getattr(b, name), -getattr(a, name), rtol=1e-15)


@pytest.mark.parametrize("kw", [dict(h_c=-0.1), dict(a_w=-1.0), dict(omega_h=float("nan"))])
def test_velocity_rejects(kw):
    args = dict(omega_h=OMEGA, h_c=H_C, a_w=A_W) | kw
    with pytest.raises(DesignError):
        ring_generator_velocities(LAW, [0.0], **args)
