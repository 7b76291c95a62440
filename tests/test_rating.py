"""wgcad rating: rim stress against closed forms and the sampled neutral line, the fatigue and bearing-life formulas
by hand, the stiffness fit, ratcheting trends, and the datasheet of every bundled template with a [bearing]."""

from __future__ import annotations

import dataclasses
import functools
import json
from math import pi, sqrt
from pathlib import Path

import numpy as np
import pytest
from conftest import d1_with_parts

from wgcad.cli import main
from wgcad.design.files import load_design
from wgcad.drive import build_drive
from wgcad.laws import Harmonic
from wgcad.rating.datasheet import ratcheting_torque
from wgcad.rating.fatigue import goodman_safety, strength
from wgcad.rating.life import bearing_life, raceway_ratings
from wgcad.rating.rim import curvature_change, rim_cycle, sampled_curvature_change
from wgcad.rating.stiffness import ThreeSegmentFit, fit_three_segments

ROOT = Path(__file__).resolve().parent.parent
BEARING_TEMPLATES = ["d1_involute", "d1_cycloidal", "d1_involute_nominal", "d2", "d2_imperfect"]


@functools.cache
def _design(name):
    return load_design(ROOT / "templates" / f"{name}.toml")


def test_cosine_law_rim_stress_is_the_thin_ring_closed_form():
    E, t, w0, r = 206e3, 1.4, 0.78, 81.14
    cyc = rim_cycle(Harmonic(w0=w0, r_m=r), E, 0.5 * t, np.linspace(0.0, 2 * pi, 3601))
    expect = 1.5 * E * t * w0 / r**2
    assert abs(cyc.sigma.max() / expect - 1.0) < 1e-6
    assert abs(cyc.sigma.min() / -expect - 1.0) < 1e-6
    assert cyc.peak_at == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("name", ["d1_involute", "d4_discrete", "d3_external"])
def test_law_curvature_agrees_with_the_sampled_neutral_line(name):
    """four-force (D1), disc (D4), external ring (D3): the laws' closed-form dtheta against w'' of 20000 samples of
    w (central differences: their O(h^2) error and the disc's kinks stay below 1e-4 of the peak; measured 5e-5 and
    8e-5), and against the curvature of the sampled curve itself, which differs by O(W0/r_m) (measured 0.45 W0/r_m)."""
    law = build_drive(_design(name)).law
    phi = np.linspace(0.0, 2 * pi, 20000, endpoint=False)
    a = curvature_change(law, phi)
    scale = np.abs(a).max()
    assert np.abs(a - sampled_curvature_change(law, phi)).max() < 1e-4 * scale
    assert np.abs(a - sampled_curvature_change(law, phi, exact=True)).max() < (law.w0 / law.r_m) * scale


def test_strength_factors_by_hand():
    """1100 MPa machined, 99 %: Shigley's k_a = 4.51 S_u^-0.265, k_e 0.814 (table 6-5), q from eq. 6-35a."""
    mat = _design("d1_involute").material
    mat = dataclasses.replace(mat, ultimate_strength_mpa=1100.0, yield_strength_mpa=None, endurance_limit_mpa=None)
    st = strength(mat, 1.4, 30.0)
    assert st.k_a == pytest.approx(4.51 * 1100.0**-0.265, rel=1e-12)
    assert st.k_e == pytest.approx(0.814, abs=6e-4)
    assert st.k_b == 1.0  # d_e = 0.808 sqrt(42) = 5.2 mm: the formula's 1.04 held at 1
    assert st.endurance_specimen == 550.0 and st.yield_ == pytest.approx(990.0)
    su = 1100.0 / 6.894757
    sqrt_a = 0.246 - 3.08e-3 * su + 1.51e-5 * su**2 - 2.67e-8 * su**3
    assert st.notch_sensitivity(0.2) == pytest.approx(1.0 / (1.0 + sqrt_a / sqrt(0.2 / 25.4)), rel=1e-12)
    # Goodman by hand: 100 MPa amplitude, 50 mean, 10 shear mean
    n = goodman_safety(100.0, 50.0, 10.0, st)
    assert n == pytest.approx(1.0 / (100.0 / st.endurance + sqrt(50.0**2 + 300.0) / 1100.0), rel=1e-12)
    assert goodman_safety(100.0, -80.0, 0.0, st) == pytest.approx(st.endurance / 100.0)


def test_bearing_life_by_hand():
    """12.7 mm balls, 24 of them, on a 144.18 mm pitch, conformity 0.52, loads 1000 N on 8 balls (none on the rest),
    2000 rpm with the flexspline turning back at 1/100: the formula of the module written out with the numbers."""
    D, dm, Z, f = 12.7, 144.18, 24, 0.52
    g = D / dm
    common = 1.3 * 98.1 * g**0.3 * D**1.8 * Z ** (-1 / 3)
    qci = common * (2 * f / (2 * f - 1)) ** 0.41 * (1 - g) ** 1.39 / (1 + g) ** (1 / 3)
    qco = common * (2 * f / (2 * f - 1)) ** 0.41 * (1 + g) ** 1.39 / (1 - g) ** (1 / 3)
    assert raceway_ratings(D, dm, Z, f, f) == pytest.approx((qci, qco), rel=1e-12)
    loads = np.zeros(Z)
    loads[:8] = 1000.0
    qe_in = (8 / 24 * 1000.0 ** (10 / 3)) ** 0.3
    qe_out = (8 / 24 * 1000.0**3) ** (1 / 3)
    li, lo = (qci / qe_in) ** 3, (qco / qe_out) ** 3
    l10 = (li ** (-10 / 9) + lo ** (-10 / 9)) ** -0.9
    res = bearing_life(loads, D, dm, f, 2000.0, -100.0)
    assert res.l10_mrev == pytest.approx(l10, rel=1e-12)
    assert res.l10_h == pytest.approx(l10 * 1e6 / (60 * 2020.0), rel=1e-12)
    # the magnitude: the inner raceway of this bearing rates about 6.7 kN (two and a half times D^1.8 ... by hand)
    assert 6000 < qci < 7500


def test_three_segment_fit_recovers_a_known_curve():
    true = ThreeSegmentFit(t1=100.0, t2=300.0, k1=2e5, k2=5e5, k3=9e5, theta0=2e-4, max_error=0, rms_error=0)
    T = np.linspace(10.0, 500.0, 15)
    fit = fit_three_segments(T, true.wind_up(T))
    # the breakpoints are searched on a grid of 4 x 15 steps between 10 and 500 N m (8.2 N m apart): 100 and 300
    # are not on it, so the fit lands within a step and the slopes within a few per cent
    assert abs(fit.t1 - 100.0) < 8.2 and abs(fit.t2 - 300.0) < 8.2
    for a, b in ((fit.k1, 2e5), (fit.k2, 5e5), (fit.k3, 9e5)):
        assert abs(a / b - 1) < 0.06
    assert fit.max_error < 0.02 * float(true.wind_up(500.0))
    grid = np.linspace(T[0], T[-1], 4 * len(T) + 1)[1:-1]
    on = ThreeSegmentFit(t1=grid[11], t2=grid[35], k1=2e5, k2=5e5, k3=9e5, theta0=2e-4, max_error=0, rms_error=0)
    exact = fit_three_segments(T, on.wind_up(T))
    assert (exact.t1, exact.t2) == (grid[11], grid[35])
    assert exact.k2 == pytest.approx(5e5, rel=1e-8) and exact.max_error < 1e-12


def _shallow(**changes):
    """D1 with teeth so short (addendum 0.05 m) that the elastic model sees a wave leave mesh at a few hundred N m."""
    d = _design("d1_involute")
    d = dataclasses.replace(d, tooth=dataclasses.replace(d.tooth, addendum_coef=0.05))
    for table, kv in changes.items():
        d = dataclasses.replace(d, **{table: dataclasses.replace(getattr(d, table), **kv)})
    return build_drive(d)


def test_ratcheting_rises_with_w0():
    """Measured: 252 N m; W0 0.976 -> 1.0 m: more than 1.2x."""
    base, above, note = ratcheting_torque(_shallow())
    assert not above and "leaves mesh" in note
    w0, _, _ = ratcheting_torque(_shallow(generator={"w0_coef": 1.0}))
    assert w0 > 1.2 * base


@pytest.mark.xfail(
    strict=True,
    reason="known limit: the ratcheting torque is found at one generator angle, so it depends on where the balls "
    "stand against the teeth: measured 478, 584, 252 and 723 N m for 18, 20, 24 and 32 balls and 244, 265 N m for "
    "12 and 11 mm balls (252 at 12.7): not the minimum over the ball phase a catalogue figure would be",
)
def test_ratcheting_falls_with_a_softer_generator():
    base, _, _ = ratcheting_torque(_shallow())
    soft, _, _ = ratcheting_torque(_shallow(bearing={"balls": 18}))
    stiff, _, _ = ratcheting_torque(_shallow(bearing={"balls": 32}))
    assert soft < base < stiff


@functools.cache
def _sheet(name, tmp):
    out = Path(tmp) / f"{name}.json"
    png = Path(tmp) / f"{name}.png"
    code = main(["rating", str(ROOT / "templates" / f"{name}.toml"), "--json", str(out), "--plot", str(png)])
    return code, json.loads(out.read_text()), png


@pytest.fixture(scope="module")
def sheets(tmp_path_factory):
    tmp = str(tmp_path_factory.mktemp("rating"))
    return lambda name: _sheet(name, tmp)


@pytest.mark.parametrize("name", BEARING_TEMPLATES)
def test_every_template_with_a_bearing_gets_a_datasheet(name, sheets, capsys):
    code, doc, png = sheets(name)
    if name == "d1_involute_nominal":
        # textbook teeth on D1 wedge at no load (README, "The source drives"): no torque meets every criterion
        assert code == 1 and not doc["rated"] and doc["rated_torque_nm"] == 0
        assert doc["criteria"]["entry_gap"]["limit_torque_nm"] == 0
        assert doc["stiffness"] is None and doc["lost_motion_arcmin"] is None
        assert doc["friction"] is None
        return
    assert code == 0 and doc["rated"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    crit = doc["criteria"]
    # the rated torque is the smallest limit, and the binding criterion is the one that sets it
    limits = {k: v["limit_torque_nm"] for k, v in crit.items()}
    assert doc["rated_torque_nm"] == pytest.approx(min(limits.values()), abs=0.11)
    assert limits[doc["binding_criterion"]] == pytest.approx(doc["rated_torque_nm"], abs=0.11)
    assert not crit[doc["binding_criterion"]]["limit_is_above"]
    # at the rated torque every criterion that has a figure holds
    fs = doc["flexspline"]
    assert min(s["goodman_safety"] for s in fs["at_rated"] if s["rated"]) >= 1.0 - 1e-3
    assert doc["bearing"]["max_ball_pressure_mpa"] <= 4200
    st = doc["stiffness"]
    assert 0 < st["t1_nm"] < st["t2_nm"] < doc["rated_torque_nm"]
    assert 1e4 < st["k1_nm_per_rad"] <= st["k3_nm_per_rad"] < 1e8
    assert doc["lost_motion_arcmin"] >= doc["windup_offset_arcmin"] > 0
    assert 1.5 < fs["root_kt"] < 3.5
    if name == "d2_imperfect":
        assert any("[imperfections]" in n for n in doc["not_checked"])
    # the bearing life at the rated torque: the interpolation between the bisection's last two levels leaves 2 %
    if name == "d1_cycloidal" and doc["bearing"]["l10_h"] < 7000 * (1 - 2e-2):
        pytest.xfail(
            "known limit (docs/models.md 4.3, bistable contact points): on the cycloidal flank a tooth's contact point "
            "has two near-equal minima (tooth 7 at 736 N m: its normal at -69.0 or -64.5 deg), the fixed point "
            "settles on either, and the largest ball load with it (1109 or 1136 N, L10 6740 to 7020 h re-solving "
            "the same torque); the datasheet re-solves the rated torque from another start than the search did"
        )
    assert doc["bearing"]["l10_h"] >= 7000 * (1 - 2e-2)


def test_rating_without_a_strength_is_refused_in_one_line(tmp_path, capsys):
    text = (ROOT / "templates" / "d1_involute.toml").read_text()
    text = "\n".join(
        line for line in text.splitlines() if not line.startswith(("ultimate_strength_mpa", "yield_strength"))
    )
    p = tmp_path / "d.toml"
    p.write_text(text)
    out = tmp_path / "x.json"
    code = main(["rating", str(p), "--json", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "material.ultimate_strength_mpa" in err[0]
    assert not out.exists()


def test_a_cam_offset_lowers_the_entry_gap_limit_and_rates_ratcheting_both_ways(sheets, tmp_path):
    """D1 with [S1]'s 40 um offset: the entry gap closes far sooner (README, "The source drives": the datasheet's
    entry-gap limits 731 N m with it and 1794 N m without; the load audit's Delta crosses zero near 1680 N m, the
    limit allowing the interference tolerance)."""
    _, plain, _ = sheets("d1_involute")
    out = tmp_path / "o.json"
    code = main(["rating", str(ROOT / "templates" / "d1_involute.toml"), "--cam-offset-um", "40", "--json", str(out)])
    doc = json.loads(out.read_text())
    assert code == 0 and doc["cam_offset_um"] == 40.0
    off = doc["criteria"]["entry_gap"]["limit_torque_nm"]
    assert 600 < off < 850 < 1650 < plain["criteria"]["entry_gap"]["limit_torque_nm"] < 1950
    assert "no_offset" in doc["ratcheting"] and "no_offset" not in plain["ratcheting"]


@pytest.mark.parametrize("n", [2, 4, 6])
def test_diaphragm_plate_against_a_numerical_solution_of_its_equation(n):
    """The closed-form plate (sum of r^n, r^(n+2), r^-n, r^(2-n)) against scipy's collocation solution of the
    harmonic's biharmonic equation f'''' + 2f'''/r - (1+2n^2) f''/r^2 + (1+2n^2) f'/r^3 + (n^4-4n^2) f/r^4 = 0
    with the same edge conditions; the stress from M_r = -D (f'' + nu (f'/r - n^2 f/r^2)) at both edges to 1e-6."""
    from scipy.integrate import solve_bvp

    from wgcad.rating.diaphragm import Diaphragm, edge_stress_factors

    p = Diaphragm(r_i=30.0, r_o=81.0, h=1.5, arm=142.0)
    E, nu = 206e3, 0.3

    def rhs(r, y):
        f, f1, f2, f3 = y
        f4 = -2 * f3 / r + (1 + 2 * n * n) * f2 / r**2 - (1 + 2 * n * n) * f1 / r**3 - (n**4 - 4 * n * n) * f / r**4
        return np.vstack([f1, f2, f3, f4])

    def bc(ya, yb):
        return np.array([ya[0], ya[1], yb[0] + p.r_o / n**2, yb[1] + 1.0])

    r = np.linspace(p.r_i, p.r_o, 400)
    sol = solve_bvp(rhs, bc, r, np.zeros((4, r.size)), tol=1e-10, max_nodes=100000)
    assert sol.success
    D = E * p.h**3 / (12 * (1 - nu**2))
    want = []
    for x in (p.r_i, p.r_o):
        f, f1, f2, _ = sol.sol(x)
        want.append(6 * -D * (f2 + nu * (f1 / x - n * n * f / x**2)) / p.h**2)
    got = edge_stress_factors(n, p, E, nu)
    assert got == pytest.approx(want, rel=1e-6)


def test_the_datasheet_rates_the_diaphragm_the_part_set_exports(sheets, tmp_path):
    """D1 without [parts]: the diaphragm is the part set's, sized for fatigue (wgcad.rating.plate_sizing), rated,
    and holds at the rated torque (the geometric default, a 1.5 mm plate clamped at the 134 mm bolt circle of
    a 14 mm annulus, had Goodman safety 0.59 there and was left out); given sizes that fail (that very default,
    stated in [parts]) fail the drive at no load (exit 1) and are named in a warning."""
    _, doc, _ = sheets("d1_involute")
    need = 1.0  # D1's [load] fatigue_safety_min (the default)
    plate = [s for s in doc["flexspline"]["at_rated"] if s["where"].startswith("diaphragm")]
    assert len(plate) == 2 and all(s["rated"] for s in plate)
    assert min(s["goodman_safety"] for s in plate) >= need
    dm = doc["flexspline"]["diaphragm_mm"]
    assert dm["bolt_circle_diameter"] < 133.85 and not dm["from_parts"]
    assert not doc["warnings"] and not any("[parts] does not give" in n for n in doc["not_checked"])
    out2 = tmp_path / "bad.json"
    bad_parts = "diaphragm_thickness = 1.5\ncup_bolt_circle_diameter = 133.85\ncup_bolt_hole_diameter = 13.5\ncup_bolt_count = 12"
    code = main(["rating", str(d1_with_parts(tmp_path, bad_parts)), "--json", str(out2)])
    bad = json.loads(out2.read_text())
    assert code == 1 and bad["binding_criterion"] == "fatigue" and not bad["rated"]
    assert len(bad["warnings"]) == 1 and bad["warnings"][0].startswith("diaphragm (1.5 mm thick")


def test_d1_datasheet_gives_the_friction_rows(tmp_path, capsys):
    js, page = tmp_path / "d1.json", tmp_path / "d1.html"
    assert main(["rating", str(ROOT / "templates" / "d1_involute.toml"), "--json", str(js), "--html", str(page)]) == 0
    text = capsys.readouterr().out
    fr = json.loads(js.read_text())["friction"]
    assert fr["tooth_friction"] == 0.07 and fr["lubricant_viscosity_mm2_s"] == 30.0
    # efficiency below 1, falling with speed at the rated torque, rising with torque at each speed
    last = fr["efficiency_curve"][-1]
    assert last["torque_nm"] == pytest.approx(json.loads(js.read_text())["rated_torque_nm"], abs=0.11)
    assert 0 < last["efficiency"][-1] < last["efficiency"][0] < 1
    etas = np.array([row["efficiency"] for row in fr["efficiency_curve"][1:]])
    assert np.all(np.diff(etas, axis=0) > 0)
    assert fr["efficiency_at_rated"] == pytest.approx(etas[-1][fr["efficiency_speeds_rpm"].index(2000.0)], abs=1e-4)
    # the input torque at rated is the output's share plus the printed losses (N mm per generator radian)
    loss = fr["losses_at_rated_nmm_per_rad"]
    parts = loss["teeth"] + loss["bearing_load_term"] + loss["bearing_viscous_term"]
    assert fr["input_torque_at_rated_nm"] == pytest.approx(last["torque_nm"] / 100 + 1e-3 * parts, abs=2e-4)
    assert (
        0 < fr["starting_torque_nm"] < fr["no_load_running_torque_nm"] == fr["efficiency_curve"][0]["input_torque_nm"]
    )
    assert not fr["self_locking"] and fr["backdriving_torque_nm"] > 0
    h = fr["hysteresis"]
    assert h["width_nm"] > 0 and h["cycle_energy_j"] > 0 and h["lost_motion_arcmin"] > h["loss_arcmin"] > 0
    assert "no-load running torque" in text and "hysteresis" in text
    html = page.read_text()
    assert "Hysteresis loop" in html and "Efficiency against torque" in html and "starting torque" in html


def test_nominal_rim_stress_of_a_cosine_law_is_the_closed_form():
    """The datasheet's nominal rim bending stress of a section, on the plain cosine law: ``1.5 E h w0 / r^2``; the
    notch stress beside it is ``K_f`` times it (no tooth loaded)."""
    from types import SimpleNamespace

    from wgcad.rating.flexspline import StressSetup, state_stresses

    E, h, w0, r = 206e3, 1.4, 0.78, 81.14
    st = strength(
        SimpleNamespace(
            ultimate_strength_mpa=1200.0,
            yield_strength_mpa=None,
            endurance_limit_mpa=None,
            surface_finish="machined",
            reliability=0.99,
        ),
        h,
        30.0,
    )
    setup = StressSetup(
        E=E,
        h1=h,
        t_cup=None,
        r_m=r,
        r_cup=r,
        y_root=0.5 * h,
        kt=2.0,
        kf=1.8,
        q=0.8,
        rho_f=0.3,
        s_f=1.5,
        r_f=r - 0.5,
        strength=st,
    )
    state = SimpleNamespace(
        model=SimpleNamespace(zs=np.array([0.0]), widths=np.array([30.0])),
        laws=[Harmonic(w0=w0, r_m=r)],
        torque_nm=0.0,
        contacts={"kind": np.zeros(0, int), "section": np.zeros(0, int), "force": np.zeros(0)},
    )
    (root,) = state_stresses(setup, state)
    expect = 1.5 * E * h * w0 / r**2
    assert root.nominal == pytest.approx(expect, rel=1e-6)
    assert float(np.abs(root.sigma).max()) == pytest.approx(1.8 * expect, rel=1e-6)
