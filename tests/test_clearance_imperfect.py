"""The clearance audit of an imperfect drive (wgcad.clearance.imperfect, docs/models.md 5, 6.2, 7)."""

import json
import math

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.clearance import imperfect as IM
from wgcad.clearance.engine import audit
from wgcad.clearance.scene import Scene
from wgcad.clearance.search import AuditSettings
from wgcad.cli import main
from wgcad.constants import REFINE_TOL
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.placement import transform
from wgcad.placement.imperfect import Imperfections, flex_poses, rigid_poses
from wgcad.report.audit import audit_json
from wgcad.services.audit import _sections

#: D2's tolerances of [S4] (docs/models.md 9), and an eccentricity of each gear
S4 = Imperfections(
    flex_runout=0.075,
    flex_runout_phase=math.radians(260),
    rigid_runout=0.075,
    cam_cam=0.08,
    cam_fixed=0.03,
    flex_ecc=0.01,
    flex_ecc_phase=1.0,
    rigid_ecc=0.012,
    rigid_ecc_phase=2.2,
    cam_flex=0.015,
    cam_flex_phase=0.3,
)


@pytest.fixture(scope="module")
def d1():
    return build_drive(load_design(TEMPLATES / "d1_involute.toml"))


def _settings(drive, step_deg, **kw):
    n = int(round(360.0 / step_deg))
    return AuditSettings(angles=np.deg2rad(np.arange(n) * (360.0 / n)), sections=_sections(drive, 3), **kw)


def test_batch_poses_are_the_reference_poses(d1):
    # the sweep's vectorised poses against wgcad.placement.imperfect.flex_poses (one angle at a time)
    secs = [float(z) for z in _sections(d1, 3)]
    for phi_h in (0.0, 0.7, 4.1):
        k = np.arange(0, 200, 7)
        got = IM.flex_poses_batch(d1, S4, np.full(k.size, phi_h), k, secs)
        for (rot, shift), z in zip(got, secs):
            r0, s0 = flex_poses(d1, S4, phi_h, teeth=k, z=z)
            np.testing.assert_allclose(rot, r0, rtol=0, atol=1e-12)
            np.testing.assert_allclose(shift, s0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_error_bound_holds_for_every_point(d1, seed):
    # The pruning rests on ErrorBound: the largest displacement of any point of a tooth relative to the
    # rigid teeth it faces (lower, upper, third nearest) must never exceed it. Random errors up to the
    # [S4] amplitudes and phases; every point of the tooth polygon, measured in the rigid tooth's frame.
    rng = np.random.default_rng(seed)
    imp = Imperfections(
        *(
            rng.uniform(0, 1) * getattr(S4, f) if not f.endswith(("phase", "install")) else rng.uniform(0, 2 * math.pi)
            for f in Imperfections.__dataclass_fields__
        )
    )
    scene = Scene(d1)
    secs = [float(z) for z in _sections(d1, 3)]
    eb = IM.ErrorBound(scene, imp, secs)
    rb_rot, rb_shift = rigid_poses(d1, imp)
    worst = 0.0
    for phi_h in rng.uniform(0, 2 * math.pi, 6):
        k = np.arange(200)
        imp_poses = IM.flex_poses_batch(d1, imp, np.full(200, phi_h), k, secs)
        per_poses = IM.flex_poses_batch(d1, Imperfections(), np.full(200, phi_h), k, secs)
        for si in range(len(secs)):
            (ri, si_), (rp, sp) = imp_poses[si], per_poses[si]
            Pi = transform(scene.flex_local, ri, si_)
            Pp = transform(scene.flex_local, rp, sp)
            lo, up, th = scene.neighbours(sp, rp)
            bound = eb.bound(k, np.array([phi_h]))[si, :, 0]
            for j in (lo, up, th):
                # the imperfect point taken into the imperfect rigid tooth's frame, then out through the perfect one's
                d = rb_rot[j] - scene.rigid_rot[j]
                c, s = np.cos(-d), np.sin(-d)
                q = Pi - rb_shift[j][:, None, :]
                back = np.stack(
                    [c[:, None] * q[..., 0] - s[:, None] * q[..., 1], s[:, None] * q[..., 0] + c[:, None] * q[..., 1]],
                    -1,
                )
                disp = np.hypot(*(back - Pp).transpose(2, 0, 1)).max(axis=1)
                assert np.all(disp <= bound), (float((disp - bound).max()), seed)
                worst = max(worst, float((disp / bound).max()))
    assert worst > 0.5  # the bound is not vacuous: it is within 2x of the real displacement somewhere


def test_zero_imperfections_give_the_perfect_audit(d1):
    st = _settings(d1, 2.0)
    ref = audit(d1, st)
    got = IM.audit_imperfect(d1, st, Imperfections())
    # the same samples, posed by another route (unfolded generator angles): equal to rounding
    assert abs(got.min_clearance - ref.min_clearance) <= 1e-9
    assert abs(got.raw["min_clearance_polygon"] - ref.raw["min_clearance_polygon"]) <= 1e-9
    assert abs(abs(audit_json(got)["worst"]["tooth_angle_deg"]) - audit_json(ref)["worst"]["tooth_angle_deg"]) <= 1e-6
    assert audit_json(got)["worst"]["section_z_mm"] == audit_json(ref)["worst"]["section_z_mm"]
    assert got.interference == ref.interference
    # entry gap and pinch: every passage is the perfect one (the mesh period holds: one per section measured)
    assert abs(got.entry_gap - ref.entry_gap) <= REFINE_TOL
    for key in ("entry_crossing", "entry_pinch"):  # NaN where the drive has no pinch: NaN on both routes
        a, b = got.findings[key].value, ref.findings[key].value
        assert (np.isnan(a) and np.isnan(b)) or abs(a - b) <= REFINE_TOL, key
    assert audit_json(got)["entry"]["section_z_mm"] == audit_json(ref)["entry"]["section_z_mm"]


def test_rigid_eccentricity_deepens_by_its_amplitude(d1):
    # Hand computation: the rigid gear shifted by e moves every flexspline tooth by -e relative to it, so no
    # clearance can fall by more than e (a signed distance moves no more than the bodies do); shifted
    # against the deepest spot's separating direction n*, that spot's penetration grows by exactly e
    # (first order; e = 2 um is far below the overlap's 58 um and the tooth's size). So the audit's
    # minimum must be c* - e. n* is found here by turning a 1 um translation of the perfect worst tooth
    # round in 0.5 deg steps on the exact curves (the polygons' separating direction is a few degrees
    # off: 12 nm of the 2 um). Tolerance: both figures' refinement (REFINE_TOL each) and the scan's
    # step, e (1 - cos 0.25 deg) = 0.02 nm.
    st = _settings(d1, 2.0)
    ref = audit(d1, st)
    scene = Scene(d1)
    z = audit_json(ref)["worst"]["section_z_mm"]
    # the worst sample itself, where it is (its zone: the mirror and the other wave's spots move the other way)
    rot, shift = flex_poses(
        d1,
        Imperfections(),
        math.radians(audit_json(ref)["worst"]["generator_angle_deg"]),
        teeth=[audit_json(ref)["worst"]["tooth"]],
        z=z,
    )
    det = IM.clearance_at_poses(scene, rot, shift)
    j = det.lo if det.lower[0] <= det.upper[0] else det.up
    th = np.radians(np.arange(0.0, 360.0, 0.5))
    t = 1e-3 * np.stack([np.cos(th), np.sin(th)], -1)
    vals = scene.exact_to(np.full(th.size, rot[0]), shift + t, np.full(th.size, j[0]))[0]  # on the exact curves
    deeper = th[int(np.argmin(vals))]  # the flexspline tooth moving this way goes deepest
    e = 2e-3
    # the rigid gear moves the other way: its eccentricity's phase is deeper + pi
    imp = Imperfections(rigid_ecc=e, rigid_ecc_phase=float(deeper + math.pi))
    got = IM.audit_imperfect(d1, st, imp)
    assert got.min_clearance == pytest.approx(
        ref.min_clearance - e, abs=2 * REFINE_TOL + e * (1 - math.cos(math.radians(0.25)))
    )


def test_chunks_and_bounds_change_nothing(d1):
    # one chunk per 5 generator angles against one chunk for the sweep, and the branch and bound against
    # every sample evaluated: the same minimum, the same spot (D2's [S4] errors on D1, coarse sweep)
    st = _settings(d1, 4.0, refine=False)
    a = IM.audit_imperfect(d1, st, S4, chunk_samples=200 * 3 * 5)
    b = IM.audit_imperfect(d1, st, S4, chunk_samples=10**9)
    brute = IM.audit_imperfect(d1, _settings(d1, 4.0, refine=False, bound=False), S4)
    assert a.counts["chunks"] == 18 and b.counts["chunks"] == 1
    assert brute.counts["evaluated"] == brute.counts["samples"]
    for r in (b, brute):
        assert r.min_clearance == a.min_clearance
        assert audit_json(r)["worst"] == audit_json(a)["worst"]
    assert a.counts["evaluated"] < 0.2 * brute.counts["evaluated"]


def test_audit_cli_honours_imperfections(tmp_path, capsys):
    text = (TEMPLATES / "d1_involute.toml").read_text() + "\n[imperfections]\n"
    for key, val in (("rigid_runout_um", "20.0"), ("cam_offset_fixed_um", "10.0")):
        text = edit_toml(text, "imperfections", key, val)
    p = tmp_path / "d1_imp.toml"
    p.write_text(text)
    out = tmp_path / "a.json"
    rc = main(["audit", str(p), "--step-deg", "2", "--json", str(out), "--no-refine", "--plot", str(tmp_path / "pic")])
    assert rc == 1  # D1 interferes
    res = json.loads(out.read_text())
    assert res["settings"]["imperfections"] is True
    assert res["settings"]["mesh_period"] is False
    assert not any("uses perfect parts" in n for n in res["not_checked"])
    assert not any("entry gap" in n and "not computed" in n for n in res["not_checked"])
    # the entry of the imperfect drive: the passage it happens in
    assert (
        res["entry_gap_um"] is not None
        and res["entry"]["tooth"] is not None
        and res["entry"]["generator_angle_deg"] is not None
    )
    for suffix in ("profile", "vs_angle", "tightest"):
        assert (tmp_path / f"pic_{suffix}.png").stat().st_size > 10_000
    text_out = capsys.readouterr().out
    assert "imperfect parts" in text_out and "entry gap Delta" in text_out and "NOT CHECKED: entry gap" not in text_out
    assert "None" not in text_out and "by the working flank" in text_out  # the edge of the smallest passage is named


def test_fixed_flexspline_keeps_the_perfect_audit_and_says_so(tmp_path):
    # the imperfect poses take the rigid gear as the housing's member: with a fixed flexspline the
    # audit stays on perfect parts and the summary says why
    text = (TEMPLATES / "d1_involute.toml").read_text() + "\n[imperfections]\n"
    text = edit_toml(edit_toml(text, "imperfections", "rigid_runout_um", "20.0"), "drive", "fixed", '"flexspline"')
    p = tmp_path / "d1_fixed_flex.toml"
    p.write_text(text)
    out = tmp_path / "a.json"
    main(["audit", str(p), "--step-deg", "4", "--json", str(out), "--quiet", "--no-refine"])
    res = json.loads(out.read_text())
    assert "imperfections" not in res["settings"]
    assert any(
        "uses perfect parts (imperfect parts are modelled with a fixed rigid gear only)" in n
        for n in res["not_checked"]
    )


@pytest.mark.parametrize("name", ["d3_external", "d1_odd"])
def test_bounds_hold_on_other_geometries(name, tmp_path):
    # external deformation (d3, no coning) and odd tooth counts (201/203: the waves interleave): the
    # bounded sweep gives the every-sample answer, and zero errors the perfect audit's
    if name == "d1_odd":
        text = (TEMPLATES / "d1_involute.toml").read_text()
        p = tmp_path / "d1_odd.toml"
        p.write_text(edit_toml(edit_toml(text, "drive", "z_flex", "201"), "drive", "z_rigid", "203"))
        design = load_design(p)
    else:
        design = load_design(TEMPLATES / f"{name}.toml")
    d = build_drive(design)
    imp = Imperfections(
        flex_runout=0.03,
        rigid_runout=0.03,
        rigid_runout_phase=0.7,
        cam_cam=0.02,
        cam_fixed=0.015,
        cam_fixed_phase=2.0,
        flex_ecc=0.01,
        rigid_ecc=0.008,
        rigid_ecc_phase=1.1,
    )
    st = _settings(d, 8.0, refine=False)
    a = IM.audit_imperfect(d, st, imp)
    b = IM.audit_imperfect(d, _settings(d, 8.0, refine=False, bound=False), imp)
    assert a.min_clearance == b.min_clearance and audit_json(a)["worst"] == audit_json(b)["worst"]
    assert abs(IM.audit_imperfect(d, st, Imperfections()).min_clearance - audit(d, st).min_clearance) <= 1e-9


def test_full_cycle_is_every_turn_of_the_flexspline_errors(tmp_path):
    # With errors tied to the flexspline (here its eccentricity), generator turn n meets them turned by the
    # flexspline's rotation 2 pi n / u_hg: its states are those of turn 0 of a drive whose flexspline
    # errors are installed that much further round (the perfect teeth are alike, so the teeth relabel).
    # So the whole cycle's minimum (--turns full: 43 turns for D4's 86/88 teeth) must equal the smallest
    # of 43 one-turn audits with those installation angles - computed independently, each its own sweep.
    # The phase is chosen so that turn 0 is not the worst (measured: -1.61 um in turn 0, -2.34 um in turn 10).
    from wgcad.audit import RunSettings, run_audit
    from wgcad.kinematics import gear_ratios
    from wgcad.placement.imperfect import full_cycle_turns

    base = (TEMPLATES / "d4_discrete.toml").read_text() + "\n[imperfections]\n"
    errs = (
        ("flex_eccentricity_um", "3.0"),
        ("flex_eccentricity_phase_deg", "270.0"),
        ("rigid_eccentricity_um", "3.0"),
        ("cam_offset_fixed_um", "2.0"),
    )

    def design(install_deg=None):
        text = base
        for key, val in errs + (
            (("flex_install_angle_deg", f"{install_deg:.12f}"),) if install_deg is not None else ()
        ):
            text = edit_toml(text, "imperfections", key, val)
        p = tmp_path / f"d4_{install_deg}.toml"
        p.write_text(text)
        return p

    assert full_cycle_turns(86, 88) == 43 and full_cycle_turns(200, 202) == 100
    # polygon figures (no refinement): the same polygons at the same poses either way
    _, full = run_audit(design(), RunSettings(step_deg=2.0, turns=None, refine=False))
    assert (
        round(full.settings.imperfect.generator_turns, 6) == 43
        and full.settings.imperfect.shortcuts_that_hold["one_generator_turn"] is False
    )
    u = gear_ratios(86, 88)["u_hg"]
    per_turn = [
        run_audit(design(math.degrees(2 * math.pi * n / u) % 360.0), RunSettings(step_deg=2.0, refine=False))[
            1
        ].min_clearance
        for n in range(43)
    ]
    assert full.min_clearance == pytest.approx(min(per_turn), abs=1e-9)
    assert per_turn[0] > min(per_turn) + 0.5e-3  # one turn alone misses it


def test_one_turn_holds_every_state_without_flexspline_errors(tmp_path):
    # housing- and cam-tied errors only: a generator turn later every tooth meets what its neighbour met
    from wgcad.audit import RunSettings, run_audit

    text = (TEMPLATES / "d4_discrete.toml").read_text() + "\n[imperfections]\n"
    for key, val in (
        ("rigid_eccentricity_um", "3.0"),
        ("rigid_runout_um", "4.0"),
        ("cam_offset_fixed_um", "2.0"),
        ("cam_offset_cam_um", "2.0"),
    ):
        text = edit_toml(text, "imperfections", key, val)
    p = tmp_path / "d4_housing.toml"
    p.write_text(text)
    _, one = run_audit(p, RunSettings(step_deg=2.0, refine=False))
    _, three = run_audit(p, RunSettings(step_deg=2.0, refine=False, turns=3))
    assert one.settings.imperfect.shortcuts_that_hold["one_generator_turn"] is True
    assert three.min_clearance == pytest.approx(one.min_clearance, abs=1e-9)


def test_turns_flag(tmp_path, capsys):
    text = (TEMPLATES / "d1_involute.toml").read_text() + "\n[imperfections]\n"
    text = edit_toml(text, "imperfections", "flex_runout_um", "20.0")
    p = tmp_path / "d1_flex.toml"
    p.write_text(text)
    out = tmp_path / "a.json"
    rc = main(["audit", str(p), "--step-deg", "4", "--no-refine", "--json", str(out)])
    assert rc == 1  # D1 interferes
    res = json.loads(out.read_text())
    assert res["settings"]["generator_turns"] == 1 and res["settings"]["full_cycle_turns"] == 100
    assert any("generator turns beyond the first 1 of the 100-turn cycle" in n for n in res["not_checked"])
    rc = main(["audit", str(p), "--step-deg", "4", "--no-refine", "--turns", "2", "--json", str(out)])
    assert json.loads(out.read_text())["settings"]["generator_turns"] == 2
    capsys.readouterr()
    for bad in ("0", "x", "1.5"):
        with pytest.raises(SystemExit) as e:
            main(["audit", str(p), "--turns", bad])
        assert e.value.code == 2
    assert "--turns" in capsys.readouterr().err
    # a perfect drive repeats every mesh period: more turns are refused, one line, exit 2
    assert main(["audit", str(TEMPLATES / "d1_involute.toml"), "--turns", "2"]) == 2
    err = capsys.readouterr().err
    assert "--turns" in err and "Traceback" not in err and err.count("\n") == 1


def _reference_crossing(drive, imp, phi_lo, phi_hi, k, z, r_tip_b, arc):
    """Bisection on the generator angle for the tooth's exact tip arc (sampled at 0.02 deg) reaching the rigid tip circle."""
    t = np.linspace(arc.t0, arc.t1, 2001)

    def radial(ph):
        rot, shift = flex_poses(drive, imp, ph, teeth=np.array([k]), z=z)
        shift = shift[0] - IM.rigid_translation(imp)
        pts = shift + arc.radius * np.stack([np.cos(rot[0] + t), np.sin(rot[0] + t)], -1)
        return r_tip_b - float(np.hypot(*pts.T).max())

    a, b = phi_lo, phi_hi
    fa = radial(a)
    assert fa * radial(b) < 0
    for _ in range(60):
        m = 0.5 * (a + b)
        fm = radial(m)
        if (fm <= 0) == (fa <= 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def test_entry_gap_of_every_passage_against_a_dense_reference(d1):
    # Each passage's crossing and gap from an independent route: the tooth's exact tip arc sampled at 0.02 deg
    # (its radial error 1e-8 mm), bisection on the generator angle, and the gap there between the two posed
    # outlines built at 0.001 um chords (shapely). The audit's smallest entry gap must be that of its passage
    # (to the refinement's 0.001 um plus the reference's 0.001 um) and no sampled passage may be smaller.
    from wgcad.clearance.imperfect_entry import passages

    st = _settings(d1, 1.0)
    got = IM.audit_imperfect(d1, st, S4)
    e = got.findings["entry_crossing"]
    assert np.isfinite(e.value) and e.details["passages"] == 3 * len(passages(Scene(d1), 1.0, 0.0, 2 * np.pi)[0])
    assert got.entry_gap <= e.value  # Delta: the crossing, or a pinch below it
    sc = Scene(d1)
    fine = build_drive(d1.design, tol=1e-6)
    rr, rs = rigid_poses(d1, S4)
    rigid_fine = [
        transform(fine.rigid.tooth_polygon(), rr[j : j + 1], rs[j : j + 1])[0] for j in range(d1.design.drive.z_rigid)
    ]
    c = 1.0 / sc.ratios["u_hg"] - 1.0

    import shapely

    def ref_gap(ph, k, z):
        rot, shift = flex_poses(d1, S4, ph, teeth=np.array([k]), z=z)
        tooth = shapely.Polygon(transform(fine.flex.tooth_polygon(), rot, shift)[0])
        return min(tooth.distance(shapely.Polygon(p)) for p in rigid_fine)

    # the reported passage: crossing bracketed around the audit's own angle
    span = np.deg2rad(0.5)
    ph = _reference_crossing(
        d1, S4, e.generator_angle - span, e.generator_angle + span, e.tooth, e.section_z, sc.r_tip_b, sc.tip_arc
    )
    assert abs(ph - e.generator_angle) < 1e-7
    assert abs(e.value - ref_gap(ph, e.tooth, e.section_z)) <= REFINE_TOL + 1e-6
    # the edge it names faces the rigid tooth the reference finds closest, and the summary names it
    from wgcad.clearance.entry import EDGES, edge_index

    rot, shift = flex_poses(d1, S4, ph, teeth=np.array([e.tooth]), z=e.section_z)
    tooth = shapely.Polygon(transform(fine.flex.tooth_polygon(), rot, shift)[0])
    nearest = int(np.argmin([tooth.distance(shapely.Polygon(p)) for p in rigid_fine]))
    isc = IM.ImperfectScene.from_scene(sc, S4)
    assert e.details["edge"] in EDGES and e.location in ("tip", "flank", "root")
    assert int(edge_index(isc, rot, isc.relative(shift))[EDGES.index(e.details["edge"])][0]) == nearest
    assert got.findings["entry_gap"].details["edge"] in EDGES
    # other passages (a sample of each section's): none below the reported gap
    from wgcad.clearance.entry import entry_crossings

    p_star = [g[1] for g in entry_crossings(sc, list(got.settings.sections), exact=False)]
    t = np.linspace(sc.tip_arc.t0, sc.tip_arc.t1, 401)
    rng = np.random.default_rng(3)
    checked = 0
    for z, p0 in zip(got.settings.sections, p_star):
        ph0, ks = passages(sc, p0, 0.0, 2 * np.pi)
        for i in rng.choice(len(ph0), 6, replace=False):
            # the crossing nearest the perfect one on a 0.05 deg grid, then bisection
            grid = ph0[i] + np.deg2rad(np.arange(-8.0, 8.01, 0.05)) / abs(c)
            f = []
            for g in grid:
                r_, s_ = flex_poses(d1, S4, g, teeth=np.array([ks[i]]), z=z)
                s_ = s_[0] - IM.rigid_translation(S4)
                arc = s_ + sc.tip_arc.radius * np.stack([np.cos(r_[0] + t), np.sin(r_[0] + t)], -1)
                f.append(sc.r_tip_b - float(np.hypot(*arc.T).max()))
            f = np.array(f)
            ch = np.nonzero((f[:-1] <= 0) != (f[1:] <= 0))[0]
            assert ch.size
            j = ch[np.argmin(np.abs(ch - len(grid) // 2))]
            ph = _reference_crossing(d1, S4, grid[j], grid[j + 1], ks[i], z, sc.r_tip_b, sc.tip_arc)
            assert ref_gap(ph, ks[i], z) >= e.value - REFINE_TOL - 1e-6
            checked += 1
    assert checked == 18


def test_generate_places_the_deformed_assembly_with_its_errors(tmp_path):
    # generate --generator-angle with [imperfections]: read back from the DXF, the rigid gear's outline has
    # moved by its eccentricity, the flexspline's by the cam offset plus its own eccentricity (a first harmonic
    # of its teeth's positions); the gears' own DXF stays nominal. (Run-out would move the outlines' centroids
    # too, by a fraction of it: the teeth are a fraction of the area. Left out here.)
    import shapely

    from wgcad.export.formats.dxf import read_dxf
    from wgcad.kinematics import gear_ratios
    from wgcad.placement.imperfect import cam_offset, rigid_translation

    errs = (
        ("rigid_eccentricity_um", "20.0"),
        ("rigid_eccentricity_phase_deg", "30.0"),
        ("flex_eccentricity_um", "12.0"),
        ("flex_eccentricity_phase_deg", "200.0"),
        ("cam_offset_fixed_um", "25.0"),
        ("cam_offset_fixed_phase_deg", "100.0"),
        ("cam_offset_cam_um", "10.0"),
    )
    text = (TEMPLATES / "d1_involute.toml").read_text() + "\n[imperfections]\n"
    for key, val in errs:
        text = edit_toml(text, "imperfections", key, val)
    p = tmp_path / "d1_imp.toml"
    p.write_text(text)
    assert (
        main(["generate", str(p), "--out", str(tmp_path / "imp"), "--generator-angle", "40", "--no-stl", "--quiet"])
        == 0
    )
    assert (
        main(
            [
                "generate",
                str(TEMPLATES / "d1_involute.toml"),
                "--out",
                str(tmp_path / "nom"),
                "--generator-angle",
                "40",
                "--no-stl",
                "--quiet",
            ]
        )
        == 0
    )
    got = read_dxf(tmp_path / "imp" / "d1_imp_phip040_000.dxf")
    nom = read_dxf(tmp_path / "nom" / "d1_involute_phip040_000.dxf")
    imp = Imperfections.from_spec(load_design(p).imperfections)
    phi_h = math.radians(40.0)

    def centroid(layers, name):
        c = shapely.Polygon(layers[name]["outlines"][0]).centroid
        return np.array([c.x, c.y])

    T = rigid_translation(imp)
    # the outlines are polygons at 1 um chords: their centroids agree to far below that (1e-4 mm)
    assert np.allclose(centroid(got, "RIGID") - centroid(nom, "RIGID"), T, atol=1e-4)
    phi_g = phi_h / gear_ratios(200, 202)["u_hg"]
    ecc = imp.flex_ecc * np.array([math.cos(imp.flex_ecc_phase + phi_g), math.sin(imp.flex_ecc_phase + phi_g)])
    # the flexspline's teeth: the cam offset and its eccentricity (to first order: a tooth shifted along the
    # deformed rim by e sin(...) is not exactly translated; 1 um covers it at W0/r_m ~ 1 %)
    assert np.allclose(
        centroid(got, "FLEXSPLINE_DEFORMED") - centroid(nom, "FLEXSPLINE_DEFORMED"),
        cam_offset(imp, phi_h, phi_g) + ecc,
        atol=1e-3,
    )
    assert np.allclose(
        centroid(got, "NEUTRAL_LINE") - centroid(nom, "NEUTRAL_LINE"), cam_offset(imp, phi_h, phi_g), atol=1e-6
    )
    # the nominal parts: the gears' own DXF is the perfect one
    a = read_dxf(tmp_path / "imp" / "d1_imp.dxf")["RIGID"]["outlines"][0]
    b = read_dxf(tmp_path / "nom" / "d1_involute.dxf")["RIGID"]["outlines"][0]
    assert np.array_equal(a, b)
    rep = json.loads((tmp_path / "imp" / "d1_imp.report.json").read_text())
    assert "nominal" in rep["imperfections"] and not any("[imperfections]" in n for n in rep["not_modelled"])
