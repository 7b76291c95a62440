"""Friction of the loaded drive: the sliding kinematics against finite differences of the placement, one contact's
loss by hand, Palmgren's terms by hand, efficiency and hysteresis trends on D1 (docs/models.md 10.8)."""

from __future__ import annotations

import dataclasses
from math import gamma, pi, sqrt
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from wgcad.design.files import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
from wgcad.friction.bearing import (
    PALMGREN_Y,
    PALMGREN_Z,
    STRIBECK_SUM,
    bearing_friction,
    palmgren_torque,
    static_rating,
)
from wgcad.friction.efficiency import FrictionSetup, backdriving_torque, efficiency_table, friction_point
from wgcad.friction.hysteresis import hysteresis_loop
from wgcad.friction.teeth import tooth_friction
from wgcad.kinematics import gear_ratios
from wgcad.laws import Harmonic
from wgcad.placement.law import tooth_pose
from wgcad.placement.sliding import material_shift, sliding_rate

ROOT = Path(__file__).resolve().parent.parent
R_M, W0 = 80.0, 0.8


def _placed(law, phi, local):
    rot, sh = tooth_pose(law, phi, R_M)
    c, s = np.cos(rot), np.sin(rot)
    return np.stack([c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1]], axis=-1) + sh


def _fd_velocity(law, phi, local, rate, eps):
    """The flexspline material point's velocity against the rigid gear, generator frame, by a central difference of
    the placement: the tooth's material angle moves by ``rate eps``, the rigid gear turns by ``-eps``."""

    def rel(e):
        p = _placed(law, phi + rate * e, local)
        c, s = np.cos(e), np.sin(e)  # the rigid gear's point turned back by +e: the frame of the rigid gear
        return np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]], axis=-1)

    return (rel(eps) - rel(-eps)) / (2 * eps)


def test_sliding_rate_is_the_placements_derivative():
    law = Harmonic(w0=W0, r_m=R_M)
    rate = 1.0 / gear_ratios(200, 202)["u_hg"] - 1.0
    phi = np.array([0.05, 0.3, -0.2, 1.4, 2.9])
    local = np.array([[R_M + 1.0, 0.8], [R_M + 0.3, -0.5], [R_M + 1.5, 0.2], [R_M, 0.0], [R_M - 0.7, 1.1]])
    P = _placed(law, phi, local)
    n = np.array([[1.0, 0.0], [0.6, 0.8], [0.0, 1.0], [-0.8, 0.6], [0.28, -0.96]])
    slide, approach = sliding_rate(law, phi, P, n, R_M, rate)
    v = _fd_velocity(law, phi, local, rate, 1e-5)
    t = np.stack([-n[:, 1], n[:, 0]], axis=-1)
    # central differences: error ~ eps^2 times the third derivative (mm), far below 1e-7 mm/rad
    assert np.abs((v * t).sum(axis=1) - slide).max() < 1e-7
    assert np.abs((v * n).sum(axis=1) - approach).max() < 1e-7
    assert np.abs(slide).max() > 0.05  # the check sees real motion


def test_material_shift_at_the_major_axis_is_the_change_of_w():
    a, b = Harmonic(w0=W0, r_m=R_M), Harmonic(w0=W0 + 0.01, r_m=R_M)
    P = np.array([[R_M + W0 + 1.0, 0.0]])
    d = material_shift(a, b, np.array([0.0]), P, R_M)
    # at the major axis v = theta = 0 for both laws: the tooth moves out by the change of w0 alone
    assert d[0] == pytest.approx([0.01, 0.0], abs=1e-12)


def _one_contact_state(N, phi, local, normal, torque_sign=1.0):
    law = Harmonic(w0=W0, r_m=R_M)
    P = _placed(law, np.array([phi]), local[None])
    model = SimpleNamespace(
        drive=SimpleNamespace(r_m=R_M), scene=SimpleNamespace(ratios={"u_hg": -100.0}), torque_sign=torque_sign
    )
    contacts = {
        "kind": np.array([0, 1]),
        "section": np.array([0, 0]),
        "tooth": np.array([-1, 3]),
        "flank": np.array([-1, 0]),
        "phi": np.array([0.0, phi]),
        "force": np.array([500.0, N]),
        "point": np.vstack([[R_M, 0.0], P]),
        "normal": np.array([[1.0, 0.0], normal]),
    }
    return SimpleNamespace(model=model, contacts=contacts, laws=[law], torque_nm=10.0), law, P


def test_one_sliding_contact_loses_mu_n_v():
    N, mu, phi = 700.0, 0.08, 0.35
    normal = np.array([0.6, -0.8])
    local = np.array([R_M + 1.2, 0.6])
    st, law, P = _one_contact_state(N, phi, local, normal)
    fr = tooth_friction(st, mu)
    v = _fd_velocity(law, np.array([phi]), local[None], 1.0 / -100.0 - 1.0, 1e-5)[0]
    v_t = float(v @ np.array([-normal[1], normal[0]]))
    assert abs(v_t) > 0.1
    assert fr.loss == pytest.approx(mu * N * abs(v_t), rel=1e-8)
    assert fr.force.tolist() == [N]  # the ball is not a tooth contact
    # the friction force's moment about the axis, by hand: -mu N sign(v) t at P
    s_h = 1.0  # torque_sign +1, u < 0: the generator turns counter-clockwise
    f = -mu * N * np.sign(s_h * v_t) * np.array([-normal[1], normal[0]])
    m = P[0, 0] * f[1] - P[0, 1] * f[0]
    assert fr.output_moment == pytest.approx(m, rel=1e-12)
    assert fr.generator_moment + fr.output_moment / 100.0 == pytest.approx(fr.loss, rel=1e-12)


def test_palmgren_terms_by_hand():
    p1, c0, dm, nu, n, f0 = 5000.0, 60000.0, 144.0, 30.0, 2020.0, 2.0
    b = palmgren_torque(p1, c0, dm, nu, n, f0)
    assert b.load == pytest.approx(0.0005 * (5000 / 60000) ** 0.55 * 5000 * 144, rel=1e-12)
    assert b.viscous == pytest.approx(1e-7 * 2 * (30 * 2020) ** (2 / 3) * 144**3, rel=1e-12)
    slow = palmgren_torque(p1, c0, dm, 10.0, 100.0, f0)  # nu n = 1000 < 2000: the constant branch
    assert slow.viscous == pytest.approx(160e-7 * 2 * 144**3, rel=1e-12)
    assert palmgren_torque(p1, c0, dm, nu, 0.0, f0).viscous == 0.0
    assert (PALMGREN_Z, PALMGREN_Y) == (0.0005, 0.55)


def test_stribeck_sum_and_the_static_rating():
    # the sum of a zero-clearance bearing's ball loads over its radial load, by summing over many balls
    Z = 200000
    psi = (np.arange(Z) + 0.5) * 2 * pi / Z
    q = np.maximum(np.cos(psi), 0.0) ** 1.5
    assert STRIBECK_SUM == pytest.approx(q.sum() / (q * np.cos(psi)).sum(), rel=1e-8)
    # Beta-function closed forms: int cos^1.5 = sqrt(pi) G(1.25)/G(1.75), int cos^2.5 = sqrt(pi) G(1.75)/G(2.25)
    assert STRIBECK_SUM == pytest.approx(gamma(1.25) * gamma(2.25) / gamma(1.75) ** 2, rel=1e-12)
    assert sqrt(pi) > 0
    # ISO 76: at C0 the most loaded ball, 5 C0 / Z, reaches 4200 MPa under p = q Q^(1/3)
    qc, balls = 400.0, 25
    c0 = static_rating(balls, qc)
    assert qc * (5 * c0 / balls) ** (1 / 3) == pytest.approx(4200.0, rel=1e-12)
    b = bearing_friction(np.array([100.0, 0.0, -5.0, 300.0]), balls, qc, 144.0, 30.0, 2020.0, 2.0)
    assert b.p1_n == pytest.approx(400.0 / STRIBECK_SUM)


def test_backdriving_torque_between_two_states_by_hand():
    setup = SimpleNamespace(ratio=100.0)
    pts = [
        SimpleNamespace(torque_nm=T, setup=setup, starting_loss=L) for T, L in ((0.0, 50.0), (10.0, 60.0), (20.0, 70.0))
    ]
    # g(T) = 1e3 T / 100 - loss: -50, 40 -> root at 10 * 50 / 90
    assert backdriving_torque(pts)[0] == pytest.approx(10 * 50 / 90, rel=1e-12)
    locked = [SimpleNamespace(torque_nm=T, setup=setup, starting_loss=1e9) for T in (0.0, 10.0)]
    assert backdriving_torque(locked) == (None, True)


@pytest.fixture(scope="module")
def d1():
    design = load_design(ROOT / "templates" / "d1_involute.toml")
    drive = build_drive(design)
    model = build_model(drive, 3)
    br = design.bearing
    dm = 2.0 * (drive.flex_rim_radius - br.outer_ring_thickness_mm) - br.ball_diameter_mm
    states, warm = [], None
    for T in (0.0, 5.0, 20.0, 50.0, 100.0, 250.0, 490.0):
        warm = solve_load(model, T, warm=warm)
        states.append(warm)
    return model, dm, states


def test_no_friction_gives_efficiency_one_and_a_closed_loop(d1):
    model, dm, states = d1
    setup = dataclasses.replace(FrictionSetup.of(model, dm, 2000.0, mu=0.0), f0=0.0, z=0.0)
    eff = efficiency_table(states, setup)
    assert np.all(eff.table[1:] == 1.0)
    assert eff.no_load_nm == 0.0 and eff.starting_nm == 0.0
    loop = hysteresis_loop(states, 0.0)
    assert loop.width_nm < 1e-9 and loop.loss_j < 1e-9
    assert np.array_equal(loop.loading, loop.unloading)


def test_efficiency_falls_with_mu_and_rises_with_torque(d1):
    model, dm, states = d1
    etas = []
    for mu in (0.0, 0.05, 0.1, 0.2):
        setup = FrictionSetup.of(model, dm, 2000.0, mu=mu)
        etas.append([p.efficiency() for p in efficiency_table(states, setup).points[1:]])
    etas = np.array(etas)
    assert np.all(np.diff(etas, axis=0) < 0)  # every torque, every step of mu
    assert np.all(np.diff(etas, axis=1) > 0)  # 5 ... 490 N m: the catalogue's rise over the low range
    # the tooth loss itself is mu times the contacts' sum of N |v|: linear in mu
    p1 = friction_point(states[-1], FrictionSetup.of(model, dm, 2000.0, mu=0.1))
    p2 = friction_point(states[-1], FrictionSetup.of(model, dm, 2000.0, mu=0.2))
    assert p2.teeth.loss == pytest.approx(2 * p1.teeth.loss, rel=1e-12) and p1.teeth.loss > 0
    # the viscous term: efficiency falls with speed
    row = efficiency_table(states, FrictionSetup.of(model, dm, 2000.0)).table[-1]
    assert np.all(np.diff(row) < 0)


def test_hysteresis_grows_with_mu(d1):
    _, _, states = d1
    loops = [hysteresis_loop(states, mu) for mu in (0.0, 0.05, 0.1)]
    w = [lp.width_nm for lp in loops]
    e = [lp.loss_j for lp in loops]
    h = [lp.hysteresis_loss for lp in loops]
    assert w[0] < 1e-9 < w[1] < w[2] and e[0] < 1e-9 < e[1] < e[2] and h[0] < h[1] < h[2]
    # linear in mu: the slips are the frictionless states'
    assert w[2] == pytest.approx(2 * w[1], rel=1e-12)


def test_loop_of_two_states_by_hand():
    # one contact at the major axis with a tangential normal: the tangent J n is radial, and the rim's move from
    # w0 to w0 + 0.01 slides it by 0.01 mm; its force 400 N then 600 N (mean 500), the output winding 1e-3 rad
    model = SimpleNamespace(drive=SimpleNamespace(r_m=R_M))

    def state(w0, F, T, th):
        c = {
            "kind": np.array([1]),
            "section": np.array([0]),
            "tooth": np.array([0]),
            "flank": np.array([1]),
            "phi": np.array([0.0]),
            "force": np.array([F]),
            "point": np.array([[R_M + W0 + 1.0, 0.3]]),
            "normal": np.array([[0.0, -1.0]]),
        }
        return SimpleNamespace(model=model, contacts=c, laws=[Harmonic(w0=w0, r_m=R_M)], torque_nm=T, wind_up=th)

    mu = 0.1
    a, b = state(W0, 400.0, 10.0, 1e-3), state(W0 + 0.01, 600.0, 30.0, 2e-3)
    loop = hysteresis_loop([b, a], mu)
    assert loop.work_nmm[0] == pytest.approx(mu * 500.0 * 0.01, rel=1e-9)
    T_f = 1e-3 * mu * 500.0 * 0.01 / 1e-3  # N m
    assert loop.friction_nm == pytest.approx([T_f, T_f], rel=1e-9)
    assert loop.width_nm == pytest.approx(2 * T_f, rel=1e-9)
    assert loop.loss_j == pytest.approx(4e-3 * mu * 500.0 * 0.01, rel=1e-9)
    # the unloading branch: 10 - 0.5 and 30 - 0.5 N m at 1 and 2 mrad; straight on to zero torque
    theta0 = 1e-3 - 1e-3 * (10.0 - T_f) / 20.0
    assert loop.hysteresis_loss == pytest.approx(2 * theta0, rel=1e-9)
    up_T, up_th, dn_T, dn_th = loop.branches()
    assert up_T.tolist() == pytest.approx([-30 + T_f, -10 + T_f, 10 + T_f, 30 + T_f])
    assert dn_th.tolist() == pytest.approx([2e-3, 1e-3, -1e-3, -2e-3])


def test_the_seals_drag_adds_between_the_rings(d1):
    model, dm, states = d1
    plain = FrictionSetup.of(model, dm, 2000.0)
    sealed = dataclasses.replace(plain, seal_nmm=50.0)
    a, b = friction_point(states[-1], plain), friction_point(states[-1], sealed)
    # the rings turn |1 - 1/u_hg| = 1.01 against each other per generator radian (D1, u_hg = -100)
    assert plain.ring_rate == pytest.approx(1.01, rel=1e-12)
    assert b.loss() - a.loss() == pytest.approx(50.0 * 1.01, rel=1e-12)
    assert b.starting_loss - a.starting_loss == pytest.approx(50.0 * 1.01, rel=1e-12)
    assert b.efficiency() < a.efficiency()
