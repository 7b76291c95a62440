"""The elastic contact model on drive D1 (docs/models.md 9): residuals, stability, physical sense, the loaded law, bad input."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_loaded_figures import REL as REL_SUMS  # the fast ring sums' accuracy against the kernel matrix

from wgcad.design import load_design, with_changes
from wgcad.drive import build_drive
from wgcad.elastic import LoadedLaw, build_model, solve_load
from wgcad.elastic.state import POSITION_TOL
from wgcad.elastic.sweep import torque_sweep
from wgcad.laws import Law
from wgcad.report.load import load_document

ROOT = Path(__file__).resolve().parents[1]
D1 = ROOT / "templates" / "d1_involute.toml"


@pytest.fixture(scope="module")
def model():
    return build_model(build_drive(load_design(D1)), 3)


@pytest.fixture(scope="module")
def sweep(model):
    return _doc(torque_sweep(model, [0.0, 1000.0, 3000.0]))


@pytest.fixture(scope="module")
def offset_sweep(model):
    return _doc(torque_sweep(model, [1000.0], cam_offset_um=40.0, cam_offset_deg=0.0))


def _doc(sw):
    """The load audit's document of a sweep (rounded figures, units in the keys) with its load states."""
    return {**load_document(sw), "states": [lv.state for lv in sw.levels]}


def test_every_body_in_equilibrium_and_contacts_complementary(sweep):
    for st, lv in zip(sweep["states"], sweep["levels"]):
        r = st.residuals
        assert r["equilibrium"] < 1e-9  # flexspline rim: net force and moment against the cup's torque
        assert r["complementarity"] < 1e-9  # linear complementarity of the last pass, relative
        # the nonlinear contact laws (Hertz balls, tooth compliance) on the exact geometry at the solution:
        # loaded contacts close to within the re-linearisation tolerance, none penetrates beyond it
        assert r["linearisation_mm"] < POSITION_TOL
        assert r["min_gap_plus_approach_mm"] > -POSITION_TOL
        c = st.contacts
        assert c["force"].min() >= 0.0


def test_reported_forces_balance_the_output_torque_exactly(sweep, offset_sweep):
    # every reported contact force (teeth from the rigid gear, balls from the cam) acts on the rim at its point
    # along -normal; their moment about the axis balances the output torque to round-off (the flexspline's
    # rotation is free; its translations and tilts stand on the cup and the output bearing, whose reactions are
    # checked member by member in tests/test_elastic_supports.py)
    for st in sweep["states"] + offset_sweep["states"]:
        c = st.contacts
        F, n, p = c["force"], c["normal"], c["point"]
        moment = -(F * (p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0])).sum() + st.model.torque_sign * 1e3 * st.torque_nm
        scale = float((F * np.hypot(p[:, 0], p[:, 1])).max())
        assert abs(moment) < 1e-9 * scale
    # the offset moves the members against their supports: the rim off the rigid gear's axis
    assert np.abs(offset_sweep["states"][0].rigid[:2]).max() > 1e-4


def test_generator_torque_is_output_over_ratio(sweep):
    # frictionless: the cam takes the balls' moment, each ball acting along the cam's normal (its slope the
    # lever, docs/models.md 4.1). Over a mesh period the power balance makes it the output over the ratio
    # exactly; one state (tooth 0 on the major axis) is one phase of that period, where the instantaneous ratio
    # and the elastic energy's rate move it by a few percent (D1: 2-6 %). Radial forces at the balls (no
    # lever) gave a third of it.
    u = abs(sweep["states"][0].model.scene.ratios["u_hg"])
    for st in sweep["states"][1:]:
        expect = 1e3 * st.torque_nm / u
        assert abs(abs(st.generator_torque) - expect) < 0.1 * expect, (st.torque_nm, st.generator_torque, expect)


def test_positions_stable_when_the_tolerance_is_halved(model, sweep):
    a = sweep["states"][1]
    b = solve_load(model, 1000.0, tol=0.5 * POSITION_TOL)
    phi = np.linspace(-np.pi, np.pi, 401)
    for la, lb in zip(a.laws, b.laws):
        sa, sb = la.state(phi), lb.state(phi)
        move = np.hypot(sa.w - sb.w, sa.v - sb.v) + 3.0 * np.abs(sa.theta - sb.theta)
        assert move.max() < 2 * POSITION_TOL  # each within one tolerance step of the fixed point


def test_loaded_law_is_a_law(sweep):
    law = sweep["states"][1].laws[0]
    assert isinstance(law, LoadedLaw) and isinstance(law, Law)
    st = law.state(np.linspace(0, 1, 5))
    assert st.w.shape == (5,)
    # the coned family: with_w0 of the section amplitude gives this section back
    again = law.with_w0(law.w0)
    assert np.allclose(again.state([0.3]).w, st.w[:1] * 0 + law.state([0.3]).w, atol=1e-15)


def test_zero_load_rim_rests_on_the_cam_at_the_design_w0(model):
    # at no load the round rim is pressed onto the cam by the balls (docs/models.md 4.1): the cam is sized so
    # that its major axis sits at the design's W0; no tooth touches (D1's side clearance), the balls hold it
    st = solve_load(model, 0.0)
    assert abs(st.law(1).w0 - model.drive.law_at(float(model.zs[1])).w0) < 1e-12
    phi0 = np.array([0.0])
    w_centre = st.laws[0].state(phi0).w[0] / model.scales[0] * 1.0
    assert abs(w_centre - model.drive.law.w0) < 1e-6
    c = st.contacts
    assert c["force"][c["kind"] == 1].max(initial=0.0) == 0.0
    assert (c["force"][c["kind"] == 0] > 0).sum() >= 4


def test_rim_on_balls_at_the_four_force_angles_is_the_four_force_law():
    # the four-force law (docs/models.md 3.4) is the ring's response to four forces at +-beta: with a ball at
    # each of those angles (36 balls from 5 deg: 35, 145, 215, 325 deg among them; 9 mm balls to fit), no
    # clearance and the cam ground to the law, the mounted rim must take the law itself, held chiefly by those
    # four balls. Only the balls' Hertz approach (6.5 um at their ~160 N) lets the rim off the law: it sinks
    # there and rests on the neighbours too, so within two approaches of the law
    from wgcad.elastic.cam import mounted

    d = with_changes(
        load_design(D1),
        bearing={"internal_clearance_um": 0.0, "fit_clearance_um": 0.0, "balls": 36, "ball_diameter_mm": 9.0},
        load={"ball_phase_deg": 5.0},
    )
    m = build_model(build_drive(d), 3)
    mt = mounted(m)
    psi = np.rad2deg(m.bearing.psi) % 360
    top4 = np.sort(np.round(psi[np.argsort(mt.force)[-4:]], 6))
    assert np.allclose(top4, [35.0, 145.0, 215.0, 325.0])
    phi = m.tables.angles[: m.tables.z_g]
    el = m.tables.tooth_field(mt.loads)
    w = el[0] + mt.rigid[0] * np.cos(phi) + mt.rigid[1] * np.sin(phi)
    law = m.drive.law.state(phi).w
    approach = float(m.bearing.approach(mt.force.max()))
    assert np.abs(w - law).max() < 2.0 * approach
    assert abs(mt.w0 - m.drive.law.w0) < 1e-6


def test_teeth_in_contact_grow_with_torque(sweep):
    n = [lv["teeth_in_contact"] for lv in sweep["levels"]]
    assert all(b >= a for a, b in zip(n, n[1:])) and n[-1] > n[0]
    w = [sum(s["working_flank_contacts"] for s in lv["sections"]) for lv in sweep["levels"]]
    assert all(b > a for a, b in zip(w, w[1:]))


def test_wind_up_grows_and_stiffness_is_of_catalogue_order(sweep):
    wind = [st.wind_up for st in sweep["states"]]
    assert all(b > a for a, b in zip(wind, wind[1:]))
    # secant stiffness to a third of the rated torque: catalogue drives of ~160 mm pitch
    # diameter are of order 1e5 - 1e6 N m/rad (docs/models.md 4.1)
    k = 1000.0 / (wind[1] - wind[0])
    assert 1e5 <= k <= 1e6


def test_entry_gap_closes_with_torque_at_every_section(sweep):
    # [S1]: the involute entry gap falls with the output torque (docs/models.md 5, Delta)
    for z in (0.0, 15.0, 30.0):
        g = [min(e["entry_gap_um"] for e in lv["entry"] if e["section_z_mm"] == z) for lv in sweep["levels"]]
        assert all(b < a for a, b in zip(g, g[1:])), (z, g)


def test_entry_gap_wind_up_closes_it_and_the_loaded_rim_opens_it(sweep):
    # docs/models.md 4.1, "Entry gap under load": the loaded state is the rim on the cam (the mounted state)
    # turned by the mesh wind-up and bent further by the tooth forces. The wind-up alone turns the teeth onto
    # the working flanks: it closes Delta at every section and wave, more with more torque (until an entering
    # tip meets its flank). The bending alone pushes the rim in against the balls: it opens Delta. Together
    # they close it, most at the inner end, where it turns negative by 3 kN m (D1, [S1])
    from dataclasses import replace

    from wgcad.elastic.cam import mounted
    from wgcad.elastic.mesh import entry_gaps
    from wgcad.elastic.rim import merge_loads

    m = sweep["states"][0].model
    psi0, loads0 = merge_loads(m.tables.angles, mounted(m).loads)

    def gaps(mod):
        return np.array(
            [
                [p.delta for p in entry_gaps(m.scene, [mod(law).shifted(ph) for ph in (0.0, np.pi) for law in st.laws])]
                for st in sweep["states"]
            ]
        )

    full = gaps(lambda law: law)
    wind = gaps(lambda law: replace(law, psi=psi0, loads=loads0))
    rim = gaps(lambda law: replace(law, rigid=(0.0, 0.0, 0.0)))
    assert np.isfinite(full).all()
    assert (np.diff(wind, axis=0) <= 0.0).all() and (wind[-1] < wind[0]).all(), wind
    assert (rim[1:] > rim[0]).all(), rim
    assert (full[-1] < full[0]).all() and full[-1].min() < 0.0 < full[0].min()


def test_cam_offset_breaks_the_waves_and_closes_the_gap_sooner(sweep, offset_sweep):
    # the offset along the major axis of wave 0 makes the waves differ; the smaller wave's Delta is below the
    # centred cam's at the same torque (1000 N m)
    lv = offset_sweep["levels"][0]
    wave = {w: min(e["entry_gap_um"] for e in lv["entry"] if e["wave"] == w) for w in (0, 1)}
    assert abs(wave[0] - wave[1]) > 1.0
    assert min(wave.values()) < sweep["levels"][1]["entry_gap_um"]


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "wgcad", *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
    )


def _design(tmp_path, extra_replace):
    text = D1.read_text()
    for a, b in extra_replace:
        assert a in text
        text = text.replace(a, b)
    p = tmp_path / "d.toml"
    p.write_text(text)
    return p


def test_bad_input_is_one_line_and_exit_2(tmp_path):
    r = _cli("audit", str(D1), "--torque-nm", "-5")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--torque-nm" in r.stderr
    for old, new, field in (
        ("internal_clearance_um = 26.0", "internal_clearance_um = -1.0", "bearing.internal_clearance_um"),
        ("youngs_modulus_gpa = 206.0", "youngs_modulus_gpa = -206.0", "material.youngs_modulus_gpa"),
        ("balls = 24 ", "balls = 24\nballs_typo = 3 ", "bearing.balls_typo"),
    ):
        p = _design(tmp_path, [(old, new)])
        r = _cli("audit", str(p), "--torque-nm", "1000")
        assert r.returncode == 2, r.stderr
        assert r.stderr.count("\n") == 1 and field in r.stderr and "Traceback" not in r.stderr


def test_bearing_that_cannot_carry_the_load(tmp_path):
    # 3 mm balls: at D1's rated 3000 N m the balls near the major axis carry ~6 kN
    p = _design(tmp_path, [("ball_diameter_mm = 12.7", "ball_diameter_mm = 3.0")])
    r = _cli("audit", str(p), "--torque-nm", "3000")
    assert r.returncode == 2 and "bearing.ball_diameter_mm" in r.stderr and "cannot carry" in r.stderr
    assert r.stderr.count("\n") == 1


def test_teeth_that_never_meet(tmp_path):
    # flexspline tips cut down to 82.3 mm and W0 = 0.4 mm (0.45 mm at the open end): the tips stay 0.17 mm inside
    # the rigid tip circle (82.92 mm)
    p = _design(
        tmp_path,
        [
            ("fillet_coef = 0.25    # assumed (docs/models.md 2.1 default)", "fillet_coef = 0.25\ntip_radius = 82.3"),
            ("w0_coef = 0.97625", "w0_coef = 0.5"),
        ],
    )
    r = _cli("audit", str(p), "--torque-nm", "500")
    assert r.returncode == 2 and "never" in r.stderr and r.stderr.count("\n") == 1


def test_cli_writes_json_and_pngs(tmp_path):
    out = tmp_path / "load"
    r = _cli(
        "audit", str(D1), "--torque-nm", "0,500", "--json", str(tmp_path / "l.json"), "--plot", str(out), "--quiet"
    )
    assert r.returncode == 0, r.stderr
    import json

    doc = json.loads((tmp_path / "l.json").read_text())
    assert [lv["torque_nm"] for lv in doc["levels"]] == [0.0, 500.0]
    for key in (
        "entry_gap_um",
        "crossing_gap_um",
        "entry_gap_at",
        "teeth_in_contact",
        "largest_tooth_force_n",
        "ball_load_n",
        "wind_up_arcmin",
        "generator_torque_nm",
        "sections",
    ):
        assert key in doc["levels"][1]
    assert (tmp_path / "load_entry_gap.png").stat().st_size > 10000
    assert (tmp_path / "load_forces.png").stat().st_size > 10000


def test_entry_gap_of_the_nominal_law_matches_the_engine(model):
    # the load audit's entry (any law's poses, docs/models.md 5) on the analytic law is the no-load audit's
    from wgcad.clearance.entry import entry_passages, section_poses
    from wgcad.elastic.mesh import entry_gaps

    zs = [float(z) for z in model.zs]
    ref = entry_passages(model.scene, section_poses(model.scene, zs), len(zs))
    got = entry_gaps(model.scene, [model.drive.law_at(z) for z in zs])
    for a, b in zip(ref, got):
        assert abs(a.delta - b.delta) < 1e-9 and abs(a.delta_phi - b.delta_phi) < 1e-9
        assert abs(a.crossing - b.crossing) < 1e-9 and np.allclose(a.crossing_gaps, b.crossing_gaps, atol=1e-9)


def test_displacements_of_many_laws_at_once_are_their_states(sweep):
    # the entry-gap search evaluates the laws of every section, wave and level together (shared ring fields
    # and nominal states); the figures must be each law's own
    from wgcad.elastic.loaded import displacements_many

    laws = [law.shifted(p) for st in sweep["states"] for law in st.laws for p in (0.0, np.pi)]
    phis = [np.linspace(-3.0, 3.0, 41) + 0.013 * k for k in range(len(laws))]
    phis[1] = phis[0]  # shared angles too
    # ``law.state`` takes the ring's field with its derivatives (the sums' four-output tables) and the joint
    # evaluation the displacements alone (three outputs): two roundings of one sum. Both are held to the kernel
    # matrix to REL_SUMS of the field's scale (tests/test_loaded_figures.py); measured apart by up to 1.5e-12 of
    # the figure's scale (numpy 2.4.6, OpenBLAS 0.3.31), while another law's or level's figures are microns away.
    for law, phi, (w, v, th) in zip(laws, phis, displacements_many(laws, phis)):
        st = law.state(phi)
        for got, want in ((w, st.w), (v, st.v), (th, st.theta)):
            assert np.abs(got - want).max() <= REL_SUMS * np.abs(want).max()


def test_a_state_does_not_depend_on_what_the_model_solved_before():
    # the model caches the nominal tooth pairs and section laws: a cold solve must give the same bits whether
    # the model is fresh or has solved other states before
    drive = build_drive(load_design(D1))
    a = solve_load(build_model(drive, 3), 1500.0)
    m = build_model(drive, 3)
    solve_load(m, 3000.0)
    solve_load(m, 500.0, 40.0)
    b = solve_load(m, 1500.0)
    assert a.wind_up == b.wind_up
    assert np.array_equal(a.contacts["force"], b.contacts["force"])
