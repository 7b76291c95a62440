"""No-load KE of imperfect drives from contact (docs/models.md 6.2, 7): lattice table and linear errors against the direct computation."""

import math

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.accuracy import ke as K
from wgcad.accuracy import ke_table
from wgcad.cli import main
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.placement.imperfect import Imperfections, flex_poses, rigid_poses, shortcuts

AS = 180.0 / math.pi * 3600.0


@pytest.fixture(scope="module")
def d2():
    # D2 as first templated: its teeth engage on both flanks at the major axis (the flank-error model's case)
    return build_drive(load_design(DESIGNS / "d2_nominal.toml"))


DESIGNS = TEMPLATES.parent / "tests" / "designs"


def _path(name):
    """A bundled template, or a test design (tests/designs: the source drives as first templated)."""
    p = TEMPLATES / f"{name}.toml"
    return p if p.exists() else DESIGNS / f"{name}.toml"


@pytest.fixture(scope="module")
def table0(d2):
    return K.contact_table(d2, Imperfections(), 8, sections=[None])


def test_perfect_parts_mesh_periodic_and_small(d2, table0):
    # the direct computation (exact poses, no table) repeats after a rigid pitch of generator rotation
    p = 2 * math.pi / 202
    for phi in (0.0031, 0.0107):
        a = K.closing_direct(d2, Imperfections(), phi, table0.side_w, sections=[None])
        b = K.closing_direct(d2, Imperfections(), phi + 7 * p, table0.side_w, sections=[None])
        assert abs(a - b) * AS < 1e-6
    res = K.kinematic_error(d2, Imperfections(), table=table0, samples=8 * 202)
    ke = res.ke
    np.testing.assert_allclose(ke[8:], ke[:-8], atol=1e-12)
    # intrinsic KE of perfect involute teeth on a non-conjugate deformation: sub-arcsecond ripple
    assert 0.0 < res.ke_pp * AS < 2.0


@pytest.mark.parametrize(
    "imp",
    [
        Imperfections(),
        Imperfections(rigid_runout=2e-3, rigid_runout_phase=0.4),
        Imperfections(flex_runout=2e-3, flex_runout_phase=1.1),
        Imperfections(rigid_ecc=1e-3, rigid_ecc_phase=0.5),
        Imperfections(flex_ecc=1e-3, flex_ecc_phase=2.0),
        Imperfections(cam_fixed=1e-3, cam_fixed_phase=0.7, cam_flex=1e-3),
        Imperfections(cam_cam=3e-3, cam_cam_phase=0.4, rigid_runout=1e-3, flex_runout=1e-3),
    ],
    ids=["perfect", "rigid_runout", "flex_runout", "rigid_ecc", "flex_ecc", "cam_fixed_flex", "cam_cam_mix"],
)
def test_table_and_linear_errors_match_the_direct_computation(d2, table0, imp):
    # The fast KE (contacts tabulated once on the lattice, errors added through each contact's
    # sensitivity) against exact poses of every tooth and a fresh contact search. Errors of 1-3 um:
    # the linear model's residual is second order, (e / r)^2-ish rotations times the lever,
    # far below 0.05 arcsec (2.4e-7 rad, 19 nm at the pitch circle); the perfect case is exact.
    tab = K.contact_table(d2, imp, 8, sections=[None])  # built for these amplitudes (which contacts to refine)
    res = K.kinematic_error(d2, imp, table=tab, samples=8 * 202 * 3)
    for i in (0, 77, 1501, 3001, 4447):
        for side, arr in ((tab.side_w, res.delta_w), (-tab.side_w, res.delta_n)):
            ref = K.closing_direct(d2, imp, res.phi_h[i], side, sections=[None])
            assert abs(arr[i] - ref) * AS < 0.05, (i, side, arr[i] * AS, ref * AS)


def test_one_eccentricity_gives_the_hand_estimate(d2, table0):
    # Rigid gear off-centre by e: in a zone its teeth move by e against the flexspline's, which
    # shifts a contact by e / (r cos alpha) of rotation (alpha = 20 deg; the table's contacts
    # have |nt| r ~ 1.05); the two zones move oppositely, once per generator turn. The KE is
    # therefore of the order of e / (r cos alpha) = 2.7'' for e = 1 um, at order |u_hg| = 100
    # (once per generator turn) or twice that (the first zone to touch rectifies it).
    e = 1e-3
    res = K.kinematic_error(
        d2, Imperfections(rigid_ecc=e), table=K.contact_table(d2, Imperfections(rigid_ecc=e), 8, sections=[None])
    )
    hand = e / (d2.rigid.r * math.cos(math.radians(20.0)))
    intr = K.kinematic_error(d2, Imperfections(), table=table0, samples=8 * 202).ke_pp
    assert 0.5 * hand < res.ke_pp - intr < 2.5 * hand
    orders, amp = K.spectrum(res)
    low = (orders > 0) & (orders < 1000)
    top = orders[low][np.argmax(amp[low])]
    assert top in (100.0, 200.0)


def test_install_angle_optimiser_against_a_brute_force_scan(d2):
    imp = Imperfections(rigid_runout=0.01, rigid_runout_phase=0.3, cam_fixed=0.004, cam_fixed_phase=1.0)
    tab = K.contact_table(d2, imp, 2, sections=[None])
    best, best_pp, grid, pp = K.optimize_install_angle(tab, imp, n_grid=18)
    # brute force: the whole KE recomputed with the angle set, on a 10 deg grid (finer than the 20 deg scan)
    brute = np.radians(np.arange(0.0, 360.0, 10.0))
    vals = np.array([K.kinematic_error(d2, imp.replace(rigid_install=g), table=tab).ke_pp for g in brute])
    # the optimiser refines to 0.2 deg, so it can only be at least as good as the 10 deg grid
    assert best_pp <= vals.min() + 1e-12
    # and no angle of a 0.5 deg brute-force grid within +-5 deg of it does better than the last
    # refinement's spacing (0.2 deg) times the curve's steepest slope (from the scan) allows
    slope = np.abs(np.diff(np.append(pp, pp[0]))).max() / np.radians(20.0)
    near = best + np.radians(np.arange(-5.0, 5.01, 0.5))
    vn = np.array([K.kinematic_error(d2, imp.replace(rigid_install=g), table=tab).ke_pp for g in near])
    assert vn.min() >= best_pp - slope * np.radians(0.2)
    # its value is the KE recomputed directly at that angle (the cos/sin split of the lever is exact)
    assert abs(K.kinematic_error(d2, imp.replace(rigid_install=best), table=tab).ke_pp - best_pp) < 1e-12


def test_shortcuts_that_hold():
    assert shortcuts(Imperfections()) == {
        **shortcuts(Imperfections()),
        "mesh_period": True,
        "identical_waves": True,
        "mirror_symmetry": True,
    }
    s = shortcuts(Imperfections(cam_cam=0.01))
    assert s["mesh_period"] and not s["identical_waves"] and s["mirror_symmetry"]
    s = shortcuts(Imperfections(cam_cam=0.01, cam_cam_phase=0.5))
    assert s["mesh_period"] and not s["mirror_symmetry"]
    assert not shortcuts(Imperfections(rigid_runout=0.01))["mesh_period"]


def test_poses_of_an_imperfect_drive(d2):
    # run-out alone turns each tooth about the axis by (F / 2r) sin(a + xi) (rigid) / along the rim (flex)
    imp = Imperfections(rigid_runout=0.02, rigid_runout_phase=0.3)
    r0, s0 = rigid_poses(d2, Imperfections())
    r1, s1 = rigid_poses(d2, imp)
    a = (np.arange(202) + 0.5) * 2 * math.pi / 202
    np.testing.assert_allclose(r1 - r0, 0.01 / d2.rigid.r * np.sin(a + 0.3), atol=1e-15)
    # a stationary cam offset translates every flexspline tooth by it (no coning at the centre section)
    f0 = flex_poses(d2, Imperfections(), 0.3)
    f1 = flex_poses(d2, Imperfections(cam_fixed=0.03, cam_fixed_phase=0.0), 0.3)
    np.testing.assert_allclose(f1[1] - f0[1], np.tile([0.03, 0.0], (200, 1)), atol=1e-13)


@pytest.mark.parametrize(
    "key,value,msg",
    [
        ("rigid_runout_um", "-5.0", "imperfections.rigid_runout_um: must be in [0, m/4"),
        ("flex_runout_phase_deg", "400.0", "imperfections.flex_runout_phase_deg: must be in [-360, 360]"),
        (
            "cam_offset_cam_um",
            "900.0",
            "imperfections.cam_offset_cam_um: must be in [0, m/4 (in um) = 200] um, got 900",
        ),
        ("runout_um", "5.0", "imperfections.runout_um: unknown key"),
    ],
)
def test_bad_imperfections_exit_2(tmp_path, capsys, key, value, msg):
    text = edit_toml((TEMPLATES / "d2_imperfect.toml").read_text(), "imperfections", key, value)
    (tmp_path / "bad.toml").write_text(text)
    code = main(["ke", str(tmp_path / "bad.toml"), "--json", str(tmp_path / "o.json")])
    err = capsys.readouterr().err
    assert code == 2
    assert msg in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "o.json").exists()


def test_bad_flag_exits_2(capsys):
    with pytest.raises(SystemExit) as e:
        main(["ke", str(TEMPLATES / "d2_imperfect.toml"), "--per-mesh", "0"])
    assert e.value.code == 2


def test_fixed_flexspline_is_refused(tmp_path, capsys):
    text = edit_toml((TEMPLATES / "d2_imperfect.toml").read_text(), "drive", "fixed", '"flexspline"')
    (tmp_path / "f.toml").write_text(text)
    assert main(["ke", str(tmp_path / "f.toml")]) == 2
    assert "drive.fixed" in capsys.readouterr().err


def _zone0(tab):
    """The table restricted to the zone around the major axis (+x)."""
    M = tab.z_g * tab.N
    for side, S in tab.sides.items():
        keep = np.abs(((S["m"] + M // 2) % M - M // 2) / M * 2 * math.pi) < 0.5 * math.pi
        tab.sides[side] = {k: v[keep] for k, v in S.items()}
    return tab


@pytest.mark.parametrize(
    "error",
    [dict(flex_ecc=1.0, flex_ecc_phase=0.3), dict(flex_runout=2.0, flex_runout_phase=1.1)],
    ids=["flex eccentricity", "flex run-out"],
)
def test_contact_ke_agrees_with_the_double_flank_formula_to_first_order(d2, error):
    # docs/models.md 6.1: in double-flank engagement [S2]'s dT is the mesh's tangential motion that takes up the
    # errors in a zone (the radial parts cancel between the flanks). The contact model's double-flank position
    # (the centre between the working and the other flank's contact, one zone) must turn the flexspline back by
    # dT over the contact radius, to first order in the error. The drive's errors enter [S2]'s formula through
    # accuracy.drive_flank_errors (run-out along the line of action, the drive's own phases); the other errors'
    # mapping is checked exactly against the drive's poses (tests/test_flank_errors.py): here the contacts
    # themselves, which spread about the zone's axis, against [S2]'s point zone.
    from wgcad.accuracy.flank_errors import drive_flank_errors

    n = 4 * 202 * 5 // 4  # 1.25 generator turns: the flexspline's terms go once round
    theta = {}
    for e in (0.0, 1e-3, 2e-3):
        imp = Imperfections(**{k: (v * e if not k.endswith("phase") else v) for k, v in error.items()})
        tab = _zone0(K.contact_table(d2, imp, 4, sections=[None]))
        res = K.kinematic_error(d2, imp, table=tab, samples=n)
        theta[e] = tab.side_w * 0.5 * (res.delta_w - res.delta_n)
        phi_h, side_w = res.phi_h, tab.side_w
        R = float(np.hypot(*tab.sides[side_w]["q"].T).mean())  # contact radius
    d1, d2_ = theta[1e-3] - theta[0.0], theta[2e-3] - theta[0.0]
    # first order: doubling the error doubles the change (the second-order residual is ~e^2 / r)
    assert np.abs(d2_ - 2 * d1).max() < 0.02 * np.abs(d1).max()
    imp1 = Imperfections(**{k: (v * 1e-3 if not k.endswith("phase") else v) for k, v in error.items()})
    dT = drive_flank_errors(d2, imp1, phi_h, "double").dT
    # the flexspline turns back by dT / R; 3 % covers the contacts' spread about the zone's axis
    # (teeth within +-10 deg: the tangential direction there differs by cos 10 deg = 0.985)
    np.testing.assert_allclose(d1, -dT / R, atol=0.03 * np.abs(dT).max() / R)


def test_contact_normals_do_not_depend_on_the_search_path():
    # A contact's normal (hence its sensitivity nt) was read at the search's last iterate; where a corner
    # meets the other outline that direction depends on the path the search took, and on D2 with its
    # [S4] errors 11 % of the KE samples were 4 to 35 arcsec off the direct computation (exact poses,
    # fresh contact search), among them these. It is now read at a fixed 10 nm gap (contact.BACKOFF).
    # The linear model's own residual at the [S4] amplitudes (0.1 mm, second order) measured 0.55 arcsec
    # at most over 60 random samples (centre section, 8 per mesh): 1 arcsec here.
    drive = build_drive(load_design(TEMPLATES / "d2_imperfect.toml"))
    imp = Imperfections.from_spec(drive.design.imperfections)
    tab = K.contact_table(drive, imp, 8, sections=[None])
    a = K.kinematic_error(drive, imp, table=tab)
    for i, side, arr in (
        (59, 1, a.delta_w),
        (74, 1, a.delta_w),
        (82, 1, a.delta_w),
        (1041, -1, a.delta_n),
        (158450, 1, a.delta_w),
    ):
        ref = K.closing_direct(drive, imp, a.phi_h[i], side * tab.side_w, sections=[None])
        assert abs(arr[i] - ref) * AS < 1.0, (i, arr[i] * AS, ref * AS)


def test_deep_overlaps_are_flagged_where_the_linear_model_fails():
    # Validity range of the linear error model (ke.DEEP_OVERLAP): on D2 as first templated (textbook teeth) with
    # its [S4] errors the open end (z = 0) interferes so deeply that every first contact turns back by > 600''
    # to separate, and there the table's closing rotations are hundreds of arcsec off the direct computation;
    # mid-face (z = 16) no first contact is that deep and they agree within 2'' (measured 1.8'' at most).
    drive = build_drive(load_design(DESIGNS / "d2_imperfect_nominal.toml"))
    imp = Imperfections.from_spec(drive.design.imperfections)
    worst = {}
    for z in (0.0, 16.0):
        tab = K.contact_table(drive, imp, 8, sections=[z])
        res = K.kinematic_error(drive, imp, table=tab, samples=8 * 202 * 4)
        errs = [
            abs(res.delta_n[i] - K.closing_direct(drive, imp, res.phi_h[i], -tab.side_w, sections=[z])) * AS
            for i in (101, 1733, 2900, 5631 % len(res.ke), 6001)
        ]
        worst[z] = (res.deep_overlap_fraction, max(errs))
    assert worst[0.0][0] == 1.0 and worst[0.0][1] > 100.0
    assert worst[16.0][0] == 0.0 and worst[16.0][1] < 2.0


def test_finite_differences_started_near_the_contact_equal_those_from_rest(monkeypatch):
    # The FD sensitivities' solves start 1 um of gap before the unperturbed contact (ke_table._FD_START) rather
    # than from rest. Both end at the same convergence test (1e-8 mm gap), so the sensitivities agree to
    # the FD's own noise, 1e-10 rad / 1e-4 mm = 1e-6 rad/mm on |nt| ~ 1/80 per mm: 1e-4 relative, and the
    # KE to ~0.1 mm x 1e-6 rad/mm = 1e-7 rad = 0.02 arcsec. D2 [S4], open end, 8 per mesh.
    drive = build_drive(load_design(TEMPLATES / "d2_imperfect.toml"))
    imp = Imperfections.from_spec(drive.design.imperfections)
    near = K.contact_table(drive, imp, 8, sections=[0.0])
    monkeypatch.setattr(ke_table, "_FD_START", 0.0)
    rest = K.contact_table(drive, imp, 8, sections=[0.0])
    for side in (1, -1):
        a, b = near.sides[side]["nt"], rest.sides[side]["nt"]
        assert np.abs(a - b).max() <= 1e-4 * np.abs(b).max()
    a = K.kinematic_error(drive, imp, table=near, samples=8 * 202 * 10)
    b = K.kinematic_error(drive, imp, table=rest, samples=8 * 202 * 10)
    assert np.abs(a.ke - b.ke).max() * AS < 0.02


def test_a_tip_running_into_the_root_fillet_is_followed_by_the_table():
    # D4 as templated: at the major axis the flexspline tip reaches 18.340 mm, 3 um short of the end of
    # the rigid involute (18.343 mm, then a 0.1 mm root fillet). A few um of radial error (sweep sample
    # of tests/test_sweep_yield.py, seed 9 #1) carry the contact into the fillet, where the closing
    # rotation's slope changes (4.3x steeper on the working side). The table linearised the flank
    # contact alone: 31 % of 401 samples were 0.5 to 18.7 arcsec off the direct computation (exact poses,
    # fresh search; at i = 58495 17.96'' against 3.09'') and the largest KE read 92.94'' instead of 107.95''.
    # Each pair's further features are now candidates too (ke._second_features): over the 401 samples
    # 0.029'' at most with the table built for these errors, 0.049'' with the one built for the sweep's
    # largest (40, 15, 20 um); 0.1'' is the tolerance (the linear model's second-order residual at these
    # errors, cf. the D2 tests above).
    drive = build_drive(load_design(TEMPLATES / "d4_discrete.toml"))
    imp = Imperfections(
        rigid_runout=12.191382894030646e-3, flex_ecc=4.115553110055613e-3, cam_fixed=7.163634705787521e-3
    )
    big = imp.replace(rigid_runout=40e-3, flex_ecc=15e-3, cam_fixed=20e-3)
    for tab in (K.contact_table(drive, imp), K.contact_table(drive, big)):
        res = K.kinematic_error(drive, imp, table=tab)
        for i in (0, 58495, 18724, 38807):
            for side, arr in ((tab.side_w, res.delta_w), (-tab.side_w, res.delta_n)):
                ref = K.closing_direct(drive, imp, res.phi_h[i], side)
                assert abs(arr[i] - ref) * AS < 0.1, (i, side, arr[i] * AS, ref * AS)


@pytest.mark.parametrize(
    "name, scale, pruned",
    [
        ("d2_imperfect", 1.0, False),
        ("d2_imperfect", 0.4, True),
        ("d2_imperfect_nominal", 1.0, True),
        ("d4_discrete", None, False),
    ],
)
def test_pruned_table_gives_the_exhaustive_ke(name, scale, pruned):
    # the table searches for second features only the pairs that can be first (ke_table._can_be_first,
    # a bound on every line's change over the error amplitudes) and starts each search where the pair's
    # own line puts it; the reference searches every pair from rest. The KE and the installation-angle
    # curve must be the same: to every digit where the searches find the same contacts, else within the
    # searches' convergence (GAP_TOL 1e-8 mm at 80 mm is 2.6e-5'' of closing rotation; 1.3e-4'' measured
    # on D4, 0 on D2; 1e-3'' is the tolerance)
    drive = build_drive(load_design(_path(name)))
    if scale is None:  # D4 with errors of the sweep's order (tests/test_sweep_yield.py)
        imp = Imperfections(
            flex_runout=0.02,
            flex_runout_phase=math.radians(260),
            rigid_runout=0.02,
            cam_cam=0.01,
            cam_fixed=0.008,
            rigid_ecc=0.004,
            rigid_ecc_phase=2.2,
            flex_ecc=0.003,
            flex_ecc_phase=1.0,
        )
    else:
        full = Imperfections.from_spec(drive.design.imperfections)
        imp = full.replace(
            flex_runout=scale * full.flex_runout,
            rigid_runout=scale * full.rigid_runout,
            cam_fixed=scale * full.cam_fixed,
            rigid_ecc=0.01 * scale,
            rigid_ecc_phase=1.0,
            flex_ecc=0.005 * scale,
        )
    fast = K.contact_table(drive, imp)
    ref = K.contact_table(drive, imp, exhaustive=True)
    if pruned:  # the pruning was exercised
        assert len(fast.sides[1]["g"]) < len(ref.sides[1]["g"])
    a, b = K.kinematic_error(drive, imp, table=fast), K.kinematic_error(drive, imp, table=ref)
    for x, y in ((a.delta_w, b.delta_w), (a.delta_n, b.delta_n)):
        assert np.array_equal(np.isfinite(x), np.isfinite(y))
        fin = np.isfinite(x)
        assert np.abs(x[fin] - y[fin]).max() * AS < 1e-3
    ang = np.linspace(0.0, 2 * math.pi, 8, endpoint=False)
    assert np.abs(K.install_angle_scan(fast, imp, ang) - K.install_angle_scan(ref, imp, ang)).max() * AS < 1e-3


@pytest.mark.parametrize("name", ["d2_imperfect", "d4_discrete"])
def test_lanes_drop_only_contacts_that_are_never_first(name, monkeypatch):
    # candidate_lanes keeps per lattice class the candidates that can be first, from a bound that compares each contact
    # with its group's best through both contacts' sensitivities (second features included). The KE with
    # every contact of the class as a candidate must be the same, sample by sample.
    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    imp = (
        Imperfections.from_spec(drive.design.imperfections)
        if name == "d2_imperfect"
        else Imperfections(
            flex_runout=0.02,
            rigid_runout=0.02,
            cam_cam=0.01,
            cam_fixed=0.008,
            rigid_ecc=0.004,
            rigid_ecc_phase=2.2,
            flex_ecc=0.003,
            flex_ecc_phase=1.0,
        )
    )
    tab = K.contact_table(drive, imp)
    I = 4096
    a = K.kinematic_error(drive, imp, table=tab, samples=I)

    def every(tab_, side, imp_, slack=1.05):
        S = tab_.sides[side]
        cls = [np.nonzero(S["m"] % tab_.N == c)[0] for c in (-tab_.sigma * np.arange(tab_.N)) % tab_.N]
        out = np.full((tab_.N, max(len(x) for x in cls)), -1, dtype=int)
        for r, x in enumerate(cls):
            out[r, : len(x)] = x
        return out

    pruned = (K.candidate_lanes(tab, tab.side_w, imp) >= 0).sum()
    assert pruned < 0.5 * (every(tab, tab.side_w, imp) >= 0).sum()  # the lanes do drop most contacts
    monkeypatch.setattr(K, "candidate_lanes", every)
    b = K.kinematic_error(drive, imp, table=tab, samples=I)
    np.testing.assert_array_equal(a.delta_w, b.delta_w)
    np.testing.assert_array_equal(a.delta_n, b.delta_n)


ALL_ERRORS = dict(
    flex_runout=0.075,
    flex_runout_phase=1.3,
    rigid_runout=0.06,
    rigid_runout_phase=-0.4,
    rigid_ecc=0.009,
    rigid_ecc_phase=-1.1,
    flex_ecc=0.012,
    flex_ecc_phase=0.7,
    cam_cam=0.08,
    cam_cam_phase=0.5,
    cam_flex=0.015,
    cam_flex_phase=2.0,
    cam_fixed=0.03,
    cam_fixed_phase=1.6,
    rigid_install=0.4,
    flex_install=-0.9,
)


@pytest.mark.parametrize("name", ["d2_imperfect", "d4_discrete"])
def test_harmonic_form_is_the_linear_error_terms(name):
    # Every error is a first harmonic over the teeth or the generator angle, so each contact's linear terms are
    # Re(A_e . w(i)) with three waves shared by all contacts (docs/models.md 6.2); the KE evaluates them so.
    # Held to the term-by-term formulas (error_terms: tooth indices, rigid pitches and normals per sample) at
    # random samples, every error kind and installation angle at once, to float rounding (1e-15 rad against
    # terms of ~1e-3 rad).
    from wgcad.accuracy.ke_lanes import error_terms, harmonic_terms, harmonics

    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    imp = Imperfections(**ALL_ERRORS)
    tab = K.contact_table(drive, imp)
    i = np.sort(np.random.default_rng(5).choice(K._record(tab), 3000, replace=False))
    for side in tab.sides:
        lanes = K.candidate_lanes(tab, side, imp)
        e = lanes[i % tab.N]
        pad = e < 0
        e = np.where(pad, 0, e)
        for grp in ("cam", "rigid", "flex"):
            ref = error_terms(tab, side, imp, i[:, None], e, grp)
            got = harmonic_terms(tab, lanes, harmonics(tab, side, imp, (grp,)), i)
            assert np.abs(ref[~pad]).max() > 1e-5  # the group does act
            assert np.abs(got - ref)[~pad].max() < 1e-15


@pytest.mark.parametrize("name", ["d2_imperfect", "d4_discrete"])
def test_lane_minimum_prunes_only_what_cannot_be_first(name):
    # lane_minimum evaluates in each block of samples only the lanes whose chord, widened by the waves' bend,
    # can come below the block's best; the minimum over every lane at every sample must be the same.
    from wgcad.accuracy.ke_lanes import harmonic_terms, harmonics, lane_minimum

    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    imp = Imperfections(**ALL_ERRORS)
    tab = K.contact_table(drive, imp)
    i = np.arange(0, 20000)
    for side in tab.sides:
        lanes = K.candidate_lanes(tab, side, imp)
        A = harmonics(tab, side, imp)
        g = tab.sides[side]["g"]
        e = lanes[i % tab.N]
        full = np.where(e >= 0, g[np.maximum(e, 0)] + harmonic_terms(tab, lanes, A, i), np.inf)
        ref = full.min(axis=1)
        for block in (4, 16, 64):
            val, first = lane_minimum(tab, lanes, g, A, i, block=block)
            assert np.abs(val - ref).max() < 1e-15
            # the contact named is one that takes the minimum
            hit = e == first[:, None]
            assert np.all(np.abs(np.where(hit, full, np.inf).min(axis=1) - ref) < 1e-15)


def _table_arrays(tab):
    return {(side, key): np.asarray(v) for side, S in tab.sides.items() for key, v in S.items()}


def test_closing_measurements_split_between_threads_equal_one_thread(d2, monkeypatch):
    """The closing rotation's nearest points are measured on two threads when a call has many pairs (shapely
    releases the GIL): the contact table is the one a single thread builds, to the bit."""
    from wgcad.clearance import threads

    imp = Imperfections(flex_runout=0.01, rigid_ecc=0.005)
    monkeypatch.setattr(threads, "CORES", 2)
    monkeypatch.setattr(threads, "SPLIT", 10**9)
    one = _table_arrays(K.contact_table(d2, imp, 4, sections=[None]))
    monkeypatch.setattr(threads, "SPLIT", 2)
    two = _table_arrays(K.contact_table(d2, imp, 4, sections=[None]))
    assert one.keys() == two.keys() and one
    for key in one:
        np.testing.assert_array_equal(one[key], two[key], err_msg=str(key))


def test_a_forked_process_measures_with_threads_of_its_own(d2, monkeypatch):
    """A sweep's worker forked after the parent measured has none of the parent's helper thread: it starts its own
    (a helper inherited across a fork would take the work and never run it)."""
    import multiprocessing

    from wgcad.clearance import threads

    monkeypatch.setattr(threads, "SPLIT", 2)
    monkeypatch.setattr(threads, "CORES", 2)
    K.contact_table(d2, Imperfections(), 2, sections=[None])
    assert threads._POOL is not None  # the parent's pool thread exists now
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_child_table, args=(d2, q))
    p.start()
    p.join(30)  # the child builds its table in about a second
    alive = p.is_alive()
    if alive:
        p.kill()
    assert not alive, "the forked child hung on the inherited helper"
    assert q.get(timeout=5) > 0


def _child_table(d2, q):
    tab = K.contact_table(d2, Imperfections(), 2, sections=[None])
    q.put(int(sum(len(S["g"]) for S in tab.sides.values())))


@pytest.mark.parametrize("value", ["0", "-1", "x", "101"])
def test_bad_chord_tolerance_exits_2(value, capsys):
    with pytest.raises(SystemExit) as e:
        main(["ke", str(TEMPLATES / "d2_imperfect.toml"), "--chord-tol-um", value])
    assert e.value.code == 2 and "--chord-tol-um" in capsys.readouterr().err


def test_the_chord_tolerance_shapes_the_outlines_and_the_record_says_which(tmp_path):
    """``--chord-tol-um`` is the tolerance of the outlines the KE measures (the record equals the library's at that
    tolerance, not at the default) and the JSON carries it."""
    import json

    from wgcad.services.ke import no_load

    path = TEMPLATES / "d2_imperfect.toml"
    out = tmp_path / "k.json"
    assert main(["ke", str(path), "--per-mesh", "2", "--chord-tol-um", "0.3", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["chord_tol_um"] == 0.3
    design = load_design(path)
    imp = Imperfections.from_spec(design.imperfections)
    run, lines = no_load(build_drive(design, tol=3e-4), imp, 2, str(path))
    assert run.doc == doc and any("within 0.3 um of the exact curves" in line for line in lines)
    default, _ = no_load(build_drive(design), imp, 2, str(path))
    assert default.doc["chord_tol_um"] == 1.0 and np.abs(default.res.ke - run.res.ke).max() > 1e-9
