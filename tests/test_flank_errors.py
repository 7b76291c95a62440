"""Tests of the analytic double-/single-flank error model (wgcad.accuracy.flank_errors, docs/models.md 6.1)."""

import csv
import math

import numpy as np
import pytest

from wgcad.accuracy import (
    ENGAGEMENTS,
    Eccentricities,
    flank_error_table,
    flank_errors,
    flank_errors_over_rotation,
    gear_angles,
    write_flank_error_csv,
)
from wgcad.errors import DesignError
from wgcad.kinematics import gear_ratios

ALPHA = math.radians(20.0)
ALPHA_W = math.radians(28.0)  # any working angle other than alpha keeps the two apart in the formulas
RNG = np.random.default_rng(20261123)


def _random_ecc(**zero):
    vals = dict(
        flex_geometric=RNG.uniform(0.005, 0.05),
        flex_kinematic=RNG.uniform(0.005, 0.05),
        rigid_geometric=RNG.uniform(0.005, 0.05),
        rigid_kinematic=RNG.uniform(0.005, 0.05),
        flex_phase=RNG.uniform(-math.pi, math.pi),
        rigid_phase=RNG.uniform(-math.pi, math.pi),
    )
    vals.update(zero)
    return Eccentricities(**vals)


def test_zero_errors_give_zero():
    phi = np.linspace(-20.0, 20.0, 1001)
    res = flank_errors_over_rotation(
        phi, 200, 202, Eccentricities(), ALPHA, ALPHA_W, flex_start=0.3, rigid_start=-1.1, zone=math.pi
    )
    for e in ENGAGEMENTS:
        assert res[e].dR.shape == phi.shape
        assert np.all(res[e].dR == 0.0) and np.all(res[e].dT == 0.0)


def test_double_flank_radial_error_independent_of_kinematic_eccentricities():
    phi = np.linspace(0.0, 2 * np.pi * 100, 20001)
    geo = dict(flex_geometric=0.02, rigid_geometric=0.035)
    base = flank_errors_over_rotation(phi, 200, 202, Eccentricities(**geo), ALPHA, ALPHA_W)["double"]
    for _ in range(5):
        ecc = Eccentricities(
            **geo,
            flex_kinematic=RNG.uniform(0, 0.08),
            rigid_kinematic=RNG.uniform(0, 0.08),
            flex_phase=RNG.uniform(-4, 4),
            rigid_phase=RNG.uniform(-4, 4),
        )
        res = flank_errors_over_rotation(phi, 200, 202, ecc, ALPHA, ALPHA_W)
        np.testing.assert_array_equal(res["double"].dR, base.dR)
        # ... while the tangential error and the single-flank radial error do see them
        assert np.max(np.abs(res["double"].dT - base.dT)) > 1e-3
        single0 = flank_errors_over_rotation(phi, 200, 202, Eccentricities(**geo), ALPHA, ALPHA_W)["single_left"]
        assert np.max(np.abs(res["single_left"].dR - single0.dR)) > 1e-3


def _spectrum(signal):
    """One-sided amplitude spectrum of a real periodic record (amplitude of each cosine/sine)."""
    n = len(signal)
    return 2.0 * np.abs(np.fft.rfft(signal)) / n


@pytest.mark.parametrize("z_g, z_b", [(200, 202), (300, 298)])  # D2 (internal), D3 (external deformation)
def test_each_term_at_its_order_in_the_spectrum(z_g, z_b):
    # Relative to the generator the rigid gear turns once per generator turn and the
    # flexspline z_b/z_g times: over T = z_g/gcd generator turns (here one flexspline
    # revolution, as gcd = |z_b - z_g|) the rigid-gear terms sit in bin T and the
    # flexspline's in bin T z_b/z_g, an integer (101 of 100 for D2, 149 of 150 for D3).
    turns = z_g // math.gcd(z_g, z_b)
    bin_rigid, bin_flex = turns, turns * z_b // z_g
    assert abs(gear_ratios(z_g, z_b)["u_hg"]) == turns  # = one flexspline revolution (docs/models.md 1)
    n = 8192
    phi = np.arange(n) * (2 * np.pi * turns / n)
    sa, ca, sw, cw = math.sin(ALPHA), math.cos(ALPHA), math.sin(ALPHA_W), math.cos(ALPHA_W)
    e = 0.03
    # expected amplitude of each term (docs/models.md 6.1): (engagement, component) -> amplitude
    cases = {
        "flex_geometric": ({"double": (e * sa / sw, e * ca / cw), "single_left": (e / sw, e / cw)}, bin_flex),
        "rigid_geometric": ({"double": (e * sa / sw, e * ca / cw), "single_left": (e / sw, e / cw)}, bin_rigid),
        "flex_kinematic": ({"double": (0.0, e / cw), "single_left": (e / sw, e / cw)}, bin_flex),
        "rigid_kinematic": ({"double": (0.0, e / cw), "single_left": (e / sw, e / cw)}, bin_rigid),
    }
    for name, (amps, k) in cases.items():
        res = flank_errors_over_rotation(
            phi, z_g, z_b, Eccentricities(**{name: e}), ALPHA, ALPHA_W, flex_start=0.7, rigid_start=-0.4
        )
        for eng, (a_r, a_t) in amps.items():
            for comp, amp in (("dR", a_r), ("dT", a_t)):
                spec = _spectrum(getattr(res[eng], comp))
                if amp == 0.0:
                    assert spec.max() < 1e-15, (name, eng, comp)
                    continue
                # the whole signal in one bin (leakage-free record): amplitude to rounding
                assert int(np.argmax(spec)) == k, (name, eng, comp)
                assert spec[k] == pytest.approx(amp, rel=1e-10), (name, eng, comp)
                others = np.delete(spec, k)
                assert others.max() < 1e-10 * amp, (name, eng, comp)
    # all errors together: exactly the two orders
    res = flank_errors_over_rotation(phi, z_g, z_b, _random_ecc(), ALPHA, ALPHA_W)
    for eng in ENGAGEMENTS:
        spec = _spectrum(res[eng].dT)
        assert set(np.argsort(spec)[-2:]) == {bin_rigid, bin_flex}
        assert np.sort(spec)[-3] < 1e-10 * spec.max()


def _geometric_double_flank(phi_h, z_g, z_b, m, ecc: Eccentricities, zone: float):
    """Independent reference: eccentric pitch circles turned by the drive's kinematics, their exact
    crossing with the zone's ray, flank normals, and the 2x2 contact conditions solved numerically."""
    u_hg = gear_ratios(z_g, z_b)["u_hg"]
    # gear angles relative to the generator from the gear ratio, rigid gear fixed
    th_y = phi_h / u_hg - phi_h
    th_b = -phi_h + 0.0 * phi_h
    u = np.array([math.cos(zone), math.sin(zone)])
    t = np.array([-math.sin(zone), math.cos(zone)])

    def shifts(e, th, r, sign):
        c = sign * e * np.stack([np.cos(th), np.sin(th)], axis=-1)  # centre of the pitch circle
        cu = c @ u
        s = cu + np.sqrt(r * r - np.einsum("ij,ij->i", c, c) + cu * cu)  # exact ray-circle crossing
        return s - r, c @ t

    r_y, r_b = m * z_g / 2, m * z_b / 2
    dr_y, dt_y = shifts(ecc.flex_geometric, th_y, r_y, +1.0)
    # the rigid gear's phase is counted from the direction opposite its eccentricity
    dr_b, dt_b = shifts(ecc.rigid_geometric, th_b, r_b, -1.0)
    # accumulated pitch deviation of the tooth in the zone (material angle zone - theta)
    k_y = ecc.flex_kinematic * np.sin(ecc.flex_phase - (zone - th_y))
    k_b = -ecc.rigid_kinematic * np.sin(ecc.rigid_phase - (zone - th_b))
    dr, dt, k = dr_y - dr_b, dt_y - dt_b, k_y - k_b
    n_left = dr * math.sin(ALPHA) + dt * math.cos(ALPHA) + k
    n_right = dr * math.sin(ALPHA) - dt * math.cos(ALPHA) - k
    a = np.array([[math.sin(ALPHA_W), math.cos(ALPHA_W)], [math.sin(ALPHA_W), -math.cos(ALPHA_W)]])
    sol = np.linalg.solve(a, np.stack([n_left, n_right]))
    return sol[0], sol[1], n_left


@pytest.mark.parametrize("zone", [0.0, math.pi])
def test_double_flank_against_eccentric_gear_centres(zone):
    z_g, z_b, m = 200, 202, 0.8  # D2: pitch radii 80 and 80.8 mm
    phi = np.linspace(0.0, 2 * np.pi * 100, 4001)
    diffs = []
    for scale in (1.0, 0.5):
        ecc = Eccentricities(
            flex_geometric=0.075 * scale,
            rigid_geometric=0.05 * scale,
            flex_kinematic=0.04 * scale,
            rigid_kinematic=0.06 * scale,
            flex_phase=1.1,
            rigid_phase=-2.3,
        )
        dR, dT, n_left = _geometric_double_flank(phi, z_g, z_b, m, ecc, zone)
        ty, tb = gear_angles(phi, z_g, z_b)
        model = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, "double", zone)
        # the model is the first-order term: the exact ray-circle crossing differs by
        # at most e^2 / (2 r) per gear, scaled by sin(alpha)/sin(alpha_w)
        bound = (
            math.sin(ALPHA)
            / math.sin(ALPHA_W)
            * (ecc.flex_geometric**2 / (2 * m * z_g / 2) + ecc.rigid_geometric**2 / (2 * m * z_b / 2))
        )
        err = np.max(np.abs(model.dR - dR))
        assert err <= 1.001 * bound
        # tangential displacements of a translated circle are linear: rounding only. The two
        # routes compute gear angles of up to 2 pi 101 = 635 rad differently (phi/u - phi against
        # -phi z_b/z_g), which differ by ~635 eps = 1.4e-13 rad; times amplitudes < 0.3 mm: 4e-14 mm
        np.testing.assert_allclose(model.dT, dT, rtol=0, atol=1e-13)
        left = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, "single_left", zone)
        assert np.max(np.abs(left.dR * math.sin(ALPHA_W) - n_left)) <= 1.001 * bound * math.sin(ALPHA_W)
        diffs.append(err)
        # and it is first order: the double-flank error itself is ~1e3 x the difference
        assert np.max(np.abs(dR)) > 500 * err
    # second-order remainder: halving the eccentricities quarters it
    assert diffs[0] / diffs[1] == pytest.approx(4.0, rel=0.02)


def test_double_flank_is_the_mean_of_the_single_flanks():
    phi = RNG.uniform(-50, 50, 500)
    ty, tb = gear_angles(phi, 200, 202, 0.2, 1.3)
    ecc = _random_ecc()
    d = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, "double")
    left = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, "single_left")
    right = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, "single_right")
    np.testing.assert_allclose(d.dR, 0.5 * (left.dR + right.dR), rtol=0, atol=1e-15)
    np.testing.assert_allclose(d.dT, 0.5 * (left.dT + right.dT), rtol=0, atol=1e-15)


def test_single_flank_matches_the_printed_form():
    # docs/models.md 6.1: dR = (1/sin aw)[e_yr sin(phi + a) + e_yk sin(phi + psi_y) + ...],
    # dT = (1/cos aw)[cos a (e_yr sin phi + ...) + e_yk sin(phi + psi_y) + sin a (e_yr cos phi + ...) + ...]
    ecc = _random_ecc()
    ty = RNG.uniform(-7, 7, 300)
    tb = RNG.uniform(-7, 7, 300)
    a, aw = ALPHA, ALPHA_W
    dR = (
        ecc.flex_geometric * np.sin(ty + a)
        + ecc.flex_kinematic * np.sin(ty + ecc.flex_phase)
        + ecc.rigid_geometric * np.sin(tb + a)
        + ecc.rigid_kinematic * np.sin(tb + ecc.rigid_phase)
    ) / math.sin(aw)
    dT = (
        math.cos(a) * (ecc.flex_geometric * np.sin(ty) + ecc.rigid_geometric * np.sin(tb))
        + ecc.flex_kinematic * np.sin(ty + ecc.flex_phase)
        + math.sin(a) * (ecc.flex_geometric * np.cos(ty) + ecc.rigid_geometric * np.cos(tb))
        + ecc.rigid_kinematic * np.sin(tb + ecc.rigid_phase)
    ) / math.cos(aw)
    res = flank_errors(ty, tb, ecc, a, aw, "single_left")
    np.testing.assert_allclose(res.dR, dR, rtol=0, atol=1e-15)
    np.testing.assert_allclose(res.dT, dT, rtol=0, atol=1e-15)


def test_the_two_zones_of_two_waves_see_opposite_geometric_errors():
    # a gear translated by its eccentricity moves the teeth of opposite zones in opposite
    # radial directions: averaged over both zones the geometric double-flank error cancels
    phi = np.linspace(0, 40, 777)
    ty, tb = gear_angles(phi, 200, 202)
    ecc = Eccentricities(flex_geometric=0.03, rigid_geometric=0.02)
    z0 = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, zone=0.0)
    z1 = flank_errors(ty, tb, ecc, ALPHA, ALPHA_W, zone=math.pi)
    np.testing.assert_allclose(z0.dR + z1.dR, 0.0, atol=1e-15)
    np.testing.assert_allclose(z0.dT + z1.dT, 0.0, atol=1e-15)


def test_results_are_read_only_and_broadcast():
    res = flank_errors(np.zeros((3, 1)), np.zeros((1, 4)), _random_ecc(), ALPHA, ALPHA_W)
    assert res.dR.shape == res.dT.shape == (3, 4)
    with pytest.raises(ValueError):
        res.dR[0, 0] = 1.0


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(ecc=dict(flex_geometric=-0.01)), "eccentricity.flex_geometric"),
        (dict(ecc=dict(rigid_kinematic=float("nan"))), "eccentricity.rigid_kinematic"),
        (dict(alpha=0.0), "tooth.pressure_angle_deg"),
        (dict(alpha_w=math.radians(95)), "working_pressure_angle_deg"),
        (dict(engagement="triple"), "engagement"),
    ],
)
def test_bad_input_names_the_field(kwargs, field):
    args = dict(alpha=ALPHA, alpha_w=ALPHA_W, engagement="double")
    ecc_kw = kwargs.pop("ecc", {})
    args.update(kwargs)
    with pytest.raises(DesignError) as ei:
        flank_errors(0.0, 0.0, Eccentricities(**ecc_kw), **args)
    assert ei.value.field == field
    with pytest.raises(DesignError, match="drive.z_rigid"):
        gear_angles(0.0, 200, 200)


def test_csv_rows_round_trip(tmp_path):
    deg = np.linspace(0, 360, 37)
    header, rows = flank_error_table(
        deg,
        z_flex=200,
        z_rigid=202,
        pressure_angle_deg=20,
        working_pressure_angle_deg=28,
        flex_geometric_um=30,
        rigid_kinematic_um=20,
        rigid_phase_deg=45,
    )
    assert header[0] == "generator_angle_deg" and all(h.endswith("_um") for h in header[1:])
    assert len(header) == 1 + 2 * len(ENGAGEMENTS) and len(rows) == len(deg)
    path = tmp_path / "flank.csv"
    write_flank_error_csv(path, header, rows)
    with open(path, newline="") as fp:
        back = list(csv.reader(fp))
    assert back[0] == header
    got = np.array(back[1:], dtype=float)
    np.testing.assert_allclose(got, np.array(rows), rtol=1e-8, atol=1e-9)
    # the micrometre table agrees with the mm model
    ref = flank_errors_over_rotation(
        np.radians(deg),
        200,
        202,
        Eccentricities(flex_geometric=0.03, rigid_kinematic=0.02, rigid_phase=math.pi / 4),
        ALPHA,
        ALPHA_W,
    )
    np.testing.assert_allclose(got[:, header.index("double_dT_um")], 1e3 * ref["double"].dT, rtol=1e-8, atol=1e-9)
    assert not [p for p in tmp_path.iterdir() if p.name != "flank.csv"]  # no temporary left behind


@pytest.mark.parametrize("zone", [0.0, math.pi])
def test_drive_errors_in_s2_terms_are_the_drive_poses_errors(zone):
    # accuracy.drive_displacements maps an imperfect drive's errors onto [S2]'s terms: the translations (both
    # eccentricities, the cam offsets) as radial and tangential motion of the flexspline's tooth against the
    # rigid one in the zone, the run-outs along the line of action. The same errors move the posed teeth of
    # placement.imperfect (flex_poses, rigid_poses); at whole mesh periods a flexspline tooth sits on the zone
    # and rigid teeth flank it symmetrically, so the relative motion of the posed teeth, radial and along the
    # pitch circle, must be the mapping's, dr and dt + kin / cos(alpha). Exact for the translations; the run-out
    # of the rigid gear is read between the two flanking teeth (their mean differs from the zone's value by
    # cos(pi / z_b) - 1, 1e-4 relative); all to first order in the errors: the poses turn the teeth by up to
    # theta = (F_g/2 + e_g + F_b/2) / r ~ 1e-3 rad, whose second-order part moves a point by up to r theta^2
    # (1e-4 mm), against errors of tens of micrometres (a wrong phase or factor would be off by those).
    from pathlib import Path

    from wgcad.accuracy.flank_errors import drive_displacements
    from wgcad.design import load_design
    from wgcad.drive import build_drive
    from wgcad.placement.imperfect import Imperfections, flex_poses, rigid_poses

    drive = build_drive(load_design(Path(__file__).resolve().parents[1] / "templates" / "d2.toml"))
    imp = Imperfections(
        flex_runout=0.075,
        flex_runout_phase=1.1,
        rigid_runout=0.075,
        rigid_runout_phase=-0.7,
        flex_ecc=0.01,
        flex_ecc_phase=0.3,
        rigid_ecc=0.012,
        rigid_ecc_phase=2.5,
        cam_cam=0.08,
        cam_cam_phase=1.57,
        cam_fixed=0.03,
        cam_fixed_phase=0.4,
        cam_flex=0.02,
        cam_flex_phase=2.0,
        rigid_install=0.6,
        flex_install=-0.2,
    )
    d = drive.design.drive
    z_g, z_b = d.z_flex, d.z_rigid
    sigma = 1 if d.rotation == "ccw" else -1
    alpha = math.radians(drive.design.tooth.pressure_angle_deg)
    r = drive.flex.r
    tol = r * ((0.5 * imp.flex_runout + imp.flex_ecc + 0.5 * imp.rigid_runout) / r) ** 2
    for n in (0, 7, 1013, 5050, 14141):
        phi_h = sigma * n * 2 * math.pi / z_b
        Z = zone + phi_h
        er, et = np.array([math.cos(Z), math.sin(Z)]), np.array([-math.sin(Z), math.cos(Z)])
        # the flexspline tooth on the zone: its angle zone + phi_h - phi_g on the flexspline is a whole tooth
        phi_g = phi_h * (z_g - z_b) / z_g
        k = int(round((Z - phi_g) / (2 * math.pi / z_g))) % z_g
        # a point of the tooth on its centre line at the pitch radius, with and without the errors
        p = np.array([r, 0.0])
        moved = []
        for im in (imp, Imperfections()):
            rot, shift = flex_poses(drive, im, phi_h, teeth=np.array([k]))
            moved.append(
                np.array(
                    [
                        math.cos(rot[0]) * p[0] - math.sin(rot[0]) * p[1],
                        math.sin(rot[0]) * p[0] + math.cos(rot[0]) * p[1],
                    ]
                )
                + shift[0]
            )
        df = moved[0] - moved[1]
        # the two rigid teeth flanking the zone: their mean motion at the pitch radius
        j = int(np.floor(Z / (2 * math.pi / z_b) - 0.5)) % z_b
        jj = np.array([j, (j + 1) % z_b])
        ri, si = rigid_poses(drive, imp, jj)
        r0, s0 = rigid_poses(drive, Imperfections(), jj)
        rb = drive.rigid.r
        pts = [np.stack([rb * np.cos(rr), rb * np.sin(rr)], axis=-1) + ss for rr, ss in ((ri, si), (r0, s0))]
        db = (pts[0] - pts[1]).mean(axis=0)
        rel = df - db
        dr, dt, kin = drive_displacements(drive, imp, phi_h, zone)
        assert abs(float(rel @ er) - float(dr)) < tol, (n, float(rel @ er), float(dr))
        assert abs(float(rel @ et) - float(dt + kin / math.cos(alpha))) < tol, (
            n,
            float(rel @ et),
            float(dt + kin / math.cos(alpha)),
        )
        assert np.hypot(*rel) > 0.05  # the errors do move the teeth by tens of micrometres here


def test_imperfections_from_spec_maps_every_key_with_its_unit():
    # issue 20: from_spec was a 16-argument positional constructor renaming fields; every attribute must come
    # from its own key, um -> mm and deg -> rad, and every key of the table must be used
    import dataclasses
    import math

    from wgcad.design.imperfections import ImperfectionsSpec
    from wgcad.placement.imperfect import SPEC_KEYS, Imperfections

    keys = [f.name for f in dataclasses.fields(ImperfectionsSpec) if f.name.endswith(("_um", "_deg"))]
    assert sorted(SPEC_KEYS.values()) == sorted(keys)
    assert sorted(SPEC_KEYS) == sorted(f.name for f in dataclasses.fields(Imperfections))
    values = {k: 1.0 + i for i, k in enumerate(keys)}  # a distinct value per key
    spec = ImperfectionsSpec(**values)
    imp = Imperfections.from_spec(spec)
    for attr, key in SPEC_KEYS.items():
        want = values[key] * 1e-3 if key.endswith("_um") else math.radians(values[key])
        assert getattr(imp, attr) == pytest.approx(want, rel=1e-15), attr
