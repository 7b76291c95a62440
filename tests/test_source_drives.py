"""The source drives as rebuilt from the sources (templates/d1_*.toml, d2.toml): [S1]'s tooth gaps by hand, and
what [S1] observes on its drive holding on the templates (README, "The source drives"; docs/models.md 5, 9)."""

from math import acos, cos, pi, tan
from pathlib import Path

import numpy as np
import pytest
import shapely

from wgcad.clearance.engine import AuditSettings, audit
from wgcad.clearance.scene import Scene
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model
from wgcad.elastic.sweep import torque_sweep
from wgcad.placement import tooth_pose, transform
from wgcad.report.load import load_document

ROOT = Path(__file__).resolve().parents[1]
D1_INV = ROOT / "templates" / "d1_involute.toml"
D1_CYC = ROOT / "templates" / "d1_cycloidal.toml"
D2 = ROOT / "templates" / "d2.toml"
TORQUES = [0.0, 900.0, 1500.0, 3000.0]  # [S1] reports the gaps' positions at 900 N m, the trend over 0..3 kN m


def _inv(a):
    return tan(a) - a


def _s1_gap(d, drive, law, k: int, j: int, sgn: int, r_k: float, p_flex: np.ndarray, n: np.ndarray) -> float:
    """[S1]'s gap of flexspline tooth ``k`` against rigid tooth ``j`` on its upper (``sgn`` +1) or lower (-1) side at
    no load, written from [S1]'s equations:

        delta_0k = (r_k psi_k - (s_bk + s_gk) / 2) cos(alpha_bk) + w_k sin(alpha_bk)
        delta_k  = delta_0k - w_k sin(alpha_bk) - v_k cos(alpha_bk) + e_k theta_k      (no load: lambda = Theta = 0)

    psi_k the angle from the tooth's centre line to the rigid tooth's, s_bk the rigid tooth's arc thickness at
    the contact radius r_k and s_gk the flexspline tooth's at r_k - w_k (involutes, docs/models.md 2.1), alpha_bk
    the rigid profile angle at r_k, and e_k theta_k the contact point's move along the normal when the tooth
    turns by theta_k about its rim point A. [S1] prints cos(alpha_bk) on the thickness term alone; the arc
    r_k psi_k and the thicknesses are both taken along the circle r_k, so the whole circumferential gap is
    projected on the normal here (docs/models.md 5). The v and e theta terms change sign on the lower side.
    """
    m, zg, zb = d.drive.module, d.drive.z_flex, d.drive.z_rigid
    alpha = np.deg2rad(d.tooth.pressure_angle_deg)
    rg, rb = m * zg / 2, m * zb / 2
    s_pitch = m * (pi / 2 + 2 * d.flexspline.shift * tan(alpha)) - d.flexspline.thinning
    e_pitch = m * (pi / 2 + 2 * d.rigid.shift * tan(alpha)) + d.rigid.thinning

    def s_g(R):
        return 2 * R * (s_pitch / (2 * rg) + _inv(alpha) - _inv(acos(rg * cos(alpha) / R)))

    def s_b(R):
        return 2 * pi * R / zb - 2 * R * (e_pitch / (2 * rb) + _inv(alpha) - _inv(acos(rb * cos(alpha) / R)))

    phi = 2 * pi * k / zg
    st = law.state(np.array([phi]))
    w, v, th = float(st.w[0]), float(st.v[0]), float(st.theta[0])
    psi = sgn * ((j + 0.5) * 2 * pi / zb - phi)
    a_b = acos(rb * cos(alpha) / r_k)
    delta_0 = (r_k * psi - 0.5 * (s_b(r_k) + s_g(r_k - w))) * cos(a_b) + w * sin_(a_b)
    A = np.array([(drive.r_m + w) * np.cos(phi) - v * np.sin(phi), (drive.r_m + w) * np.sin(phi) + v * np.cos(phi)])
    e_theta = -th * float(
        n @ np.array([-(p_flex - A)[1], (p_flex - A)[0]])
    )  # the point's move R90 (P - A) theta, along n
    return delta_0 - w * sin_(a_b) - sgn * v * cos(a_b) + e_theta


def sin_(a):
    return float(np.sin(a))


def test_s1_gaps_by_hand_match_the_exact_gaps():
    # D1 at no load, section z = 15 mm: every tooth from the major axis to the entry whose flanks overlap
    # radially (the pairs [S1]'s gaps are defined for), both edges. [S1]'s linearised gap neglects terms of
    # relative order w/r and theta against the exact one on the curves (about 1 % each on D1: W0/r_m = 0.010,
    # theta <= 0.015 rad), so they agree within 2 % of the gap plus 0.5 um (the second-order terms: theta^2
    # times a 3 mm lever, 0.7 um at most)
    d = load_design(D1_INV)
    drive = build_drive(d)
    sc = Scene(drive)
    law = drive.law_at(15.0)
    gb = 2 * pi / d.drive.z_rigid
    checked = 0
    for k in range(1, 26):
        phi = 2 * pi * k / d.drive.z_flex
        rot, shift = tooth_pose(law, np.array([phi]), drive.r_m)
        ju = int(np.floor(phi / gb - 0.5)) + 1
        flex = shapely.Polygon(transform(sc.flex_local, rot, shift)[0])
        for j, sgn in ((ju, 1), (ju - 1, -1)):
            exact = float(sc.exact_to(rot, shift, np.array([j]))[0][0])
            pf, pr = np.asarray(shapely.shortest_line(flex, sc.rigid_geoms[j]).coords)
            if exact > 0.3 or np.hypot(*pr) > drive.rigid.r_a + 0.1:  # the flanks engaged
                continue
            n = (pr - pf) / np.linalg.norm(pr - pf)
            s1 = _s1_gap(d, drive, law, k, j, sgn, float(np.hypot(*pr)), pf, n)
            assert abs(s1 - exact) <= 5e-4 + 0.02 * exact, (k, sgn, 1e3 * s1, 1e3 * exact)
            checked += 1
    assert checked >= 18  # D1 at z = 15 mm: 19 pairs (teeth 1-25, both edges)


def _sweeps(path):
    model = build_model(build_drive(load_design(path)), 3)
    return {e: load_document(torque_sweep(model, TORQUES, cam_offset_um=e)) for e in (0.0, 40.0)}


@pytest.fixture(scope="module")
def involute():
    return _sweeps(D1_INV)


@pytest.fixture(scope="module")
def cycloidal():
    return _sweeps(D1_CYC)


def _delta(sweep):
    return np.array([lv["entry_gap_um"] for lv in sweep["levels"]])


def _at(lv):
    """Where a level's Delta lies: tooth angle folded to the nearest major axis (deg), section."""
    at = lv["entry_gap_at"]
    a = (at["tooth_angle_deg"] + 90.0) % 180.0 - 90.0
    return a, at["section_z_mm"]


def test_no_load_positive_entry_gap_and_no_preload():
    # [S1]: both drives have a positive entry gap at no load; a designer's drive carries no preload that
    # rivals the rated forces (the no-load audit finds no interference; the elastic model no tooth force)
    for path in (D1_INV, D1_CYC, D2):
        d = load_design(path)
        drive = build_drive(d)
        res = audit(drive, AuditSettings(np.deg2rad(np.arange(0.0, 360.0, 0.5)), list(drive.sections(3))))
        assert not res.interference and res.min_clearance > 0, path
        assert res.entry_gap > 0, path
        model = build_model(drive, 3)
        sw = load_document(torque_sweep(model, [0.0, d.load.rated_torque_nm]))
        f0, f_rated = (lv["largest_tooth_force_n"] for lv in sw["levels"])
        assert sw["levels"][0]["entry_gap_um"] > 0
        assert f0 <= 0.05 * f_rated, (path, f0, f_rated)


def test_involute_entry_gap_smallest_on_the_inner_end_near_minus_43_deg(involute):
    # [S1] Fig. 4: at 900 N m the entry gap is smallest in the inner end's section at phi = -43 deg
    lv = involute[0.0]["levels"][1]
    assert lv["torque_nm"] == 900.0
    a, z = _at(lv)
    assert z == 30.0 and abs(a - (-43.0)) <= 3.0, (a, z)


def test_involute_entry_gap_closes_with_torque_and_sooner_with_a_cam_offset(involute):
    # [S1] Fig. 6: the involute's Delta falls strongly with torque and turns negative within 0..3 kN m;
    # with the cam offset e_h = 40 um it does so at a lower torque
    g0, g40 = _delta(involute[0.0]), _delta(involute[40.0])
    assert all(b < a for a, b in zip(g0, g0[1:])), g0
    assert g0[0] > 0 and g0[-1] < 0, g0
    first = lambda g: next(i for i, x in enumerate(g) if x < 0)  # noqa: E731
    assert first(g40) < first(g0), (g0, g40)
    assert involute[0.0]["entry_gap_closes"] and involute[40.0]["entry_gap_closes"]


def test_cycloidal_entry_gap_large_near_minus_41_deg_and_little_moved(involute, cycloidal):
    # [S1] Fig. 5, 6: the cycloidal drive's Delta is large, falls only a little with torque, does not close
    # over 0..3 kN m, hardly feels the 40 um cam offset; at 900 N m it lies near -41 deg
    g0, g40 = _delta(cycloidal[0.0]), _delta(cycloidal[40.0])
    assert (g0 > 100.0).all() and (g40 > 100.0).all(), (g0, g40)
    assert g0[-1] > 0.7 * g0[0]
    assert np.abs(g40 - g0).max() < 0.15 * g0.min()
    assert g0[1] > 3.0 * _delta(involute[0.0])[1]  # "much larger than in the involute drive"
    a, _ = _at(cycloidal[0.0]["levels"][1])
    assert abs(a - (-41.0)) <= 3.0, a
    assert not cycloidal[0.0]["entry_gap_closes"] and not cycloidal[40.0]["entry_gap_closes"]


D2_IMPERFECT = ROOT / "templates" / "d2_imperfect.toml"


def test_s4_elastic_interaction_lowers_the_ke_and_the_installation_angle_halves_it():
    """[S4] on its drive (templates/d2_imperfect.toml, [S4]'s errors, its supports read as the template says):
    summing the parts' errors (the rigid-body, no-load KE) "substantially overstates the KE, because of the elastic
    deformation of the links"; the loaded KE falls with the torque (single-zone engagement, which the errors cause,
    is what raises it); and turning the rigid gear lowers the largest KE "more than twice" at 80 and at 800 N m
    (its fig. 3). The loaded KE at the default sampling (404 whole mesh periods) at the design's angle and at the
    best angle the scan finds (README, "The source drives": 140 and 170 deg)."""
    from wgcad.accuracy import ke as K
    from wgcad.accuracy.ke_load import loaded_ke
    from wgcad.placement.imperfect import Imperfections

    d = load_design(D2_IMPERFECT)
    drive = build_drive(d)
    imp = Imperfections.from_spec(d.imperfections)
    no_load = K.kinematic_error(drive, imp, table=K.contact_table(drive, imp, 16)).ke_pp
    model = build_model(drive)
    at = {}
    for T, best_deg in ((80.0, 140.0), (800.0, 170.0)):
        design = loaded_ke(drive, imp, T, model=model)
        best = loaded_ke(drive, imp.replace(rigid_install=np.radians(best_deg)), T, model=model)
        at[T] = design.ke_pp
        assert design.ke_pp / best.ke_pp >= 2.0, (T, design.ke_pp, best.ke_pp)
        # the zones share the load: the lesser zone's share rises with the torque
        assert np.nanmin(design.zone_share) > 0.0
    assert at[800.0] < at[80.0] < 0.5 * no_load
