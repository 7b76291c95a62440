"""The KE under load: the elastic model of the imperfect drive at whole mesh periods (wgcad.accuracy.ke_load, docs/models.md 6.3)."""

import json
import math

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.accuracy import ke as K
from wgcad.accuracy.ke_load import loaded_ke, sample_periods
from wgcad.cli import main
from wgcad.design import load_design, with_changes
from wgcad.drive import build_drive
from wgcad.elastic import build_model
from wgcad.placement.imperfect import Imperfections

AS = 180.0 / math.pi * 3600.0
#: the elastic solve's position tolerance in these tests, mm: 1e-5 mm is 1.25e-7 rad of rim rotation at 80 mm
TOL = 1e-5


@pytest.fixture(scope="module")
def d1():
    drive = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    return drive, build_model(drive)


def test_samples_are_whole_mesh_periods_over_a_revolution():
    n = sample_periods(200, 202)
    assert n[0] == 0 and n[-1] < 100 * 202 and len(n) == 404 and np.all(np.diff(n) > 0)
    assert len(sample_periods(200, 202, 10)) == 10


def test_zero_errors_give_no_loaded_ke(d1):
    # a perfect drive is the same at every whole mesh period (docs/models.md 7): every sample is one state
    drive, model = d1
    L = loaded_ke(drive, Imperfections(), 500.0, samples=5, model=model, tol=TOL)
    assert np.abs(L.ke).max() < 2 * TOL / drive.r_m
    assert L.wind_up > 0


def test_rigid_eccentricity_is_the_opposite_stationary_cam_offset():
    # Two routes to one drive: the rigid gear shifted by e (each flexspline tooth moved by -e relative to the
    # rigid teeth, ke_load.tooth_errors) and the cam shifted by -e (the elastic model's own cam offset, which
    # the rim follows through the balls). Only relative positions matter to the contacts when the rim floats
    # (a rim held by its cup would be held on the housing's axis, which the first route moves with it), so
    # with a rim free to translate (its cup on an output bearing of no radial stiffness, kept from tilting so
    # that the offset cannot be taken up at the teeth alone) the two must give the same state at every
    # sample, to the solver's tolerance: the output's rotation and every tooth force.
    from wgcad.accuracy.ke_load import tooth_errors
    from wgcad.elastic import solve_load

    drive = build_drive(
        with_changes(
            load_design(TEMPLATES / "d1_involute.toml"),
            supports={"output_bearing_radial_n_per_mm": 0.0, "diaphragm_tilt_nm_per_rad": float("inf")},
        )
    )
    model = build_model(drive)
    e, psi = 0.015, 0.7
    ia = Imperfections(rigid_ecc=e, rigid_ecc_phase=psi)
    ib = Imperfections(cam_fixed=e, cam_fixed_phase=psi + math.pi)
    ref = solve_load(model, 500.0, tol=TOL)

    def tooth_forces(st):
        c = st.contacts
        t = c["kind"] == 1
        out = np.zeros(model.tables.z_g)
        np.add.at(out, c["tooth"][t], c["force"][t])
        return out

    moved = 0.0
    for n in (0, 4040, 12120):
        ea, ua, da = tooth_errors(model, ia, n)
        eb, ub, db = tooth_errors(model, ib, n)
        a = solve_load(model, 500.0, ua, da, tooth_errors=ea, tol=TOL)
        b = solve_load(model, 500.0, ub, db, tooth_errors=eb, tol=TOL)
        assert abs(a.output_rotation - b.output_rotation) < 4 * TOL / drive.r_m
        Fa, Fb = tooth_forces(a), tooth_forces(b)
        assert np.abs(Fa - Fb).max() < 0.01 * Fa.max()  # 1e-5 mm steps at 1e5 N/mm: 1 N against 1.4 kN
        moved = max(moved, float(np.abs(Fa - tooth_forces(ref)).max() / Fa.max()))
    # the eccentricity does move the load among the teeth (9 % of the largest), five times the agreement asked above:
    # the check is not between two unperturbed states
    assert moved > 0.05


def test_load_sharing_averages_the_errors(d1, tmp_path):
    # run-out, eccentricity and a stationary cam offset of a few tens of micrometres: unloaded, the first pair
    # to touch sets the output; under load some 18 pairs share it and their errors average out. Measured on
    # these errors at 24 samples: 23.3'' no load at the same angles, 18.1'' at 100 N m (4-6 contacts), 1.86'' at
    # 500 N m (17-19), 1.74'' at 3000 N m (44-47).
    drive, model = d1
    imp = Imperfections(
        flex_runout=0.02, flex_runout_phase=math.radians(260), rigid_runout=0.02, cam_fixed=0.01, rigid_ecc=0.01
    )
    tab = K.contact_table(drive, imp)
    res = K.kinematic_error(drive, imp, table=tab)
    L = loaded_ke(drive, imp, 500.0, samples=24, model=model)
    idx = L.periods * tab.N
    no_load = res.ke[idx] - res.ke[idx[0]]
    assert L.ke_pp < 0.5 * (no_load.max() - no_load.min())
    assert L.teeth_in_contact.min() > 12


def _d1_with_errors(tmp_path):
    text = (TEMPLATES / "d1_involute.toml").read_text() + "\n[imperfections]\n"
    for key, val in (("flex_runout_um", "20.0"), ("rigid_eccentricity_um", "10.0"), ("cam_offset_fixed_um", "10.0")):
        text = edit_toml(text, "imperfections", key, val)
    p = tmp_path / "d1_imp.toml"
    p.write_text(text)
    return p


def test_cli_torque_flag(tmp_path, capsys):
    p = _d1_with_errors(tmp_path)
    out = tmp_path / "ke.json"
    assert (
        main(
            [
                "ke",
                str(p),
                "--torque-nm",
                "500",
                "--load-samples",
                "6",
                "--json",
                str(out),
                "--plot",
                str(tmp_path / "k"),
            ]
        )
        == 0
    )
    doc = json.loads(out.read_text())
    (row,) = doc["loaded"]
    assert row["torque_nm"] == 500.0 and row["samples"] == 6 and row["ke_pp_arcsec"] >= 0
    assert (tmp_path / "k_ke_load.png").stat().st_size > 10_000
    text = capsys.readouterr().out
    assert "under 500 N m" in text and "NOT CHECKED" in text


@pytest.mark.parametrize(
    "args, field",
    [
        (["--torque-nm", "0"], "--torque-nm"),
        (["--torque-nm", "x"], "--torque-nm"),
        (["--load-samples", "1", "--torque-nm", "10"], "--load-samples"),
    ],
)
def test_cli_bad_load_flags_exit_2(tmp_path, capsys, args, field):
    p = _d1_with_errors(tmp_path)
    try:
        code = main(["ke", str(p), *args])
    except SystemExit as e:  # argparse's own refusals
        code = e.code
    assert code == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err


def test_cli_design_without_bearing_exits_2(capsys):
    assert main(["ke", str(TEMPLATES / "d3_external.toml"), "--torque-nm", "80"]) == 2
    err = capsys.readouterr().err
    assert "bearing." in err and err.count("\n") == 1


def test_install_lever_finds_the_scans_best_and_never_reports_a_worse_angle(d1):
    # The loaded installation-angle scan with as many states per angle as the final figures: its best angle must
    # be the lowest of the grid and of the two angles beside it (each computed here independently), never
    # above the design's own angle; and where the rigid gear carries no error the angle does nothing, so the
    # design's angle is the answer (lever 1), not a scan angle that is no better.
    from wgcad.accuracy.ke_load import install_lever

    drive, model = d1
    imp = Imperfections(flex_runout=0.02, rigid_runout=0.03, rigid_runout_phase=1.0, cam_fixed=0.01)
    n, grid = 12, 6
    lev = install_lever(drive, imp, 300.0, model=model, samples=n, scan_samples=n, n_grid=grid)
    ref = {}
    for a in list(2 * np.pi * np.arange(grid) / grid):
        ref[a] = loaded_ke(drive, imp.replace(rigid_install=a), 300.0, samples=n, model=model).ke_pp
    k = min(ref, key=ref.get)
    for a in (k - np.pi / grid, k + np.pi / grid):
        ref[a] = loaded_ke(drive, imp.replace(rigid_install=a), 300.0, samples=n, model=model).ke_pp
    assert np.allclose(lev.grid_pp, [ref[a] for a in 2 * np.pi * np.arange(grid) / grid], atol=1e-9)
    assert abs(lev.best.ke_pp - min(min(ref.values()), lev.design.ke_pp)) < 1e-9
    assert lev.best.ke_pp <= lev.design.ke_pp and lev.lever >= 1.0
    assert lev.lever > 1.05  # the rigid gear's run-out against the stationary offset: the angle matters here
    # no rigid-gear error: every angle is the same drive
    flat = install_lever(
        drive, imp.replace(rigid_runout=0.0), 300.0, model=model, samples=n, scan_samples=n, n_grid=grid
    )
    assert flat.best_angle == 0.0 and flat.lever == 1.0 and flat.best is flat.design


def test_the_loaded_ke_picture_joins_each_cam_phase_into_one_line():
    """D2's 404 loaded states step the cam by 0.2475 turn each: every 4th sample sees the same cam phase, so the
    picture draws 4 lines per curve (issue 23: the samples were drawn as unjoined dots that read as interleaved
    strands); a step of whole turns draws one."""
    from types import SimpleNamespace

    import matplotlib
    import matplotlib.axes

    matplotlib.use("Agg")
    from wgcad.export.pictures import ke as ke_figures

    turns = np.arange(404) * (100.0 / 404.0)
    assert ke_figures.strands(turns) == 4
    assert ke_figures.strands(np.arange(50) * 2.0) == 1
    assert ke_figures.strands(np.arange(50) * (1.0 / 3.0 + 1.0)) == 3
    # the picture: one joined line per strand and torque (plus the no-load ones)
    n = 404
    res = SimpleNamespace(
        phi_h=2 * np.pi * np.arange(n * 8) / 8 * (100.0 / 404.0) * 1.0,
        ke=np.sin(np.arange(n * 8) * 0.01),
        ke_pp=2.0,
        n_per_mesh=8,
    )
    L = SimpleNamespace(
        phi_h=2 * np.pi * turns,
        ke=np.cos(turns * 0.1),
        ke_pp=2.0,
        torque_nm=80.0,
        periods=np.arange(n),
        single_zone=np.zeros(n, dtype=bool),
        zone_share=np.full((n, 2), 0.5),
    )
    drawn = []
    real_plot = matplotlib.axes.Axes.plot

    def spy(self, *a, **k):
        drawn.append(a[2] if len(a) > 2 and isinstance(a[2], str) else k.get("ls", "-"))
        return real_plot(self, *a, **k)

    matplotlib.axes.Axes.plot = spy
    try:
        ke_figures.ke_load_png("t", res, [L])
    finally:
        matplotlib.axes.Axes.plot = real_plot
    assert sum(1 for s in drawn if s.startswith("-") and s != "-") == 8  # 4 no-load strands, 4 loaded ones, all joined


def test_chunked_parallel_run_is_the_sequential_one_and_the_cold_reference():
    # the loaded KE's states in fixed chunks (wgcad.accuracy.states): two processes give the same bits as one;
    # and every state solved cold from scratch (the reference: no warm start, a fresh model) agrees with the
    # chunked run within the position tolerance (the output's rotation at the rim's radius), at ten whole mesh
    # periods of D2 with [S4]'s errors at three torques. Within a chunk each state starts from the one whose errors
    # are nearest (a generator turn earlier), its tooth forces carried over (the fast path)
    from wgcad.accuracy.load_errors import tooth_errors
    from wgcad.accuracy.states import StateJob, solve_states
    from wgcad.elastic import solve_load
    from wgcad.elastic.state import POSITION_TOL

    d = load_design(TEMPLATES / "d2_imperfect.toml")
    drive = build_drive(d)
    imp = Imperfections.from_spec(d.imperfections)
    model = build_model(drive)
    periods = sample_periods(200, 202, 40)  # two chunks (32 and 8 states): the pool has work for two processes
    for T in (80.0, 300.0, 800.0):
        jobs = [StateJob(imp, T, periods)]
        one = solve_states(model, jobs, workers=1)[0]
        two = solve_states(model, jobs, workers=2)[0]
        assert np.array_equal(one.theta, two.theta) and np.array_equal(one.share, two.share)
        for i, n in list(enumerate(periods))[::4]:
            errs, e_um, e_deg = tooth_errors(model, imp, int(n))
            ref = solve_load(build_model(drive), T, e_um, e_deg, tooth_errors=errs)
            assert abs(ref.output_rotation - one.theta[i]) * drive.r_m < POSITION_TOL, (T, n)
