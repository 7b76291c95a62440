"""The 2D clearance engine: distances against closed forms, shortcuts against the full computation (docs/models.md 5, 7)."""

from math import pi

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES, edit_toml

from wgcad.clearance.distance import Template, signed_clearance
from wgcad.clearance.engine import AuditSettings, Scene, audit, brute_force_min, tooth_clearance
from wgcad.design import load_design, with_changes
from wgcad.drive import build_drive
from wgcad.placement import tooth_pose
from wgcad.report.audit import audit_json


def square(side=1.0):
    h = side / 2
    return np.array([[-h, -h], [h, -h], [h, h], [-h, h]])


def ngon(r, n):
    t = np.linspace(0, 2 * pi, n, endpoint=False)
    return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)


def pair(a, b, rot_a, sh_a, rot_b, sh_b):
    return signed_clearance(
        Template(a), np.atleast_1d(rot_a), np.atleast_2d(sh_a), Template(b), np.atleast_1d(rot_b), np.atleast_2d(sh_b)
    )[0]


# ---------------------------------------------------------------- closed forms
@pytest.mark.parametrize("gap", [0.5, 1e-3, 1e-7])
def test_squares_at_known_separation(gap):
    assert pair(square(), square(), 0, [0, 0], 0, [1 + gap, 0.3]) == pytest.approx(gap, abs=1e-12)


@pytest.mark.parametrize("depth", [0.2, 1e-3, 1e-6])
def test_overlapping_squares_report_penetration_depth(depth):
    # offset diagonally so only one corner enters: depth = that corner's distance to the nearest edge
    assert pair(square(), square(), 0, [0, 0], 0, [1 - depth, 1 - 3 * depth]) == pytest.approx(-depth, abs=1e-12)


def test_rotated_square_corner_to_edge():
    # a square turned 45 deg: its corner sits at half a diagonal from its centre
    g = 0.01
    c = 0.5 + g + np.sqrt(2) / 2
    assert pair(square(), square(), 0, [0, 0], pi / 4, [c, 0.0]) == pytest.approx(g, abs=1e-12)


def test_offset_circles():
    # inscribed 4000-gons of radii 3 and 2 at centre distance 5.5: 0.5 apart, up to the
    # polygons' sagitta r (1 - cos(pi/n)) per circle
    r1, r2, n, D = 3.0, 2.0, 4000, 5.5
    d = pair(ngon(r1, n), ngon(r2, n), 0, [0, 0], 0.3, [D, 0])
    sag = (r1 + r2) * (1 - np.cos(pi / n))
    assert D - r1 - r2 <= d <= D - r1 - r2 + sag + 1e-12


def test_tooth_and_its_mirror_beyond_the_tip():
    # the flexspline tooth of D1 and its mirror image in the line x = c: their tips are
    # 2 (c - r_a) apart (the tip arc's vertex on the centre line is at r_a exactly)
    drive = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    t = drive.flex.tooth_polygon()
    c = drive.flex.r_a + 0.05
    mirror = (np.array([2 * c, 0.0]) - t * [1, -1])[::-1]  # reflected x -> 2c - x, kept counter-clockwise
    assert pair(t, mirror, 0, [0, 0], 0, [0, 0]) == pytest.approx(0.1, abs=1e-12)


# ---------------------------------------------------------------- the engine
@pytest.fixture(scope="module")
def d4():
    return build_drive(load_design(TEMPLATES / "d4_discrete.toml"))


@pytest.fixture(scope="module")
def d1():
    return build_drive(load_design(TEMPLATES / "d1_involute.toml"))


def test_tooth_angle_reduction_matches_the_real_tooth(d1):
    # docs/models.md 7: the engine evaluates a tooth at angle phi with the material angle
    # phi (z_b - z_g)/z_b; the real tooth k at generator angle phi_h must be congruent
    scene = Scene(d1)
    zg, zb = 200, 202
    for phi_h in (0.0, 0.37, 2.1):
        k = np.arange(0, zg, 17)
        mat = 2 * pi * k / zg + phi_h * (-(zb - zg) / zg)
        phi = mat - phi_h
        rot, shift = tooth_pose(d1.law, phi, d1.r_m, frame_angle=phi_h)
        lo, up, _ = scene.neighbours(shift, rot)
        real = np.minimum(scene.clearance_to(rot, shift, lo), scene.clearance_to(rot, shift, up))
        red = tooth_clearance(scene, (phi + pi) % (2 * pi) - pi, None, third=False)
        np.testing.assert_allclose(np.minimum(red.lower, red.upper), real, atol=1e-12)


SHORTCUTS = ["use_period", "use_waves", "use_mirror", "cull", "bound"]


def _audit(drive, step_deg, k, **kw):
    # the polygon engine (refine=False) unless a test asks: these tests are about the search,
    # tests/test_exact.py about the figures on the exact curves
    kw.setdefault("refine", False)
    angles = np.deg2rad(np.arange(0, 360, step_deg))
    return audit(drive, AuditSettings(angles=angles, sections=drive.sections(k), **kw))


@pytest.mark.parametrize("name,step,k", [("d4_discrete", 2.0, 1), ("d1_involute", 3.0, 3)])
def test_each_shortcut_gives_the_full_answer(name, step, k):
    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    full = _audit(drive, step, k, **{s: False for s in SHORTCUTS})
    fast = _audit(drive, step, k)
    # the same samples are evaluated exactly; mirrored ones agree to rounding
    assert fast.min_clearance == pytest.approx(full.min_clearance, abs=1e-11)
    assert fast.entry_gap == pytest.approx(full.entry_gap, abs=1e-11)
    for s in SHORTCUTS:
        one_off = _audit(drive, step, k, **{s: False})
        assert one_off.min_clearance == pytest.approx(full.min_clearance, abs=1e-11), s
    # and the shortcuts really skip work
    assert fast.counts["evaluated"] < full.counts["evaluated"] / 5
    assert fast.counts["unique_tooth_angles"] < full.counts["unique_tooth_angles"] / 3


def test_engine_equals_brute_force(d4):
    angles = np.deg2rad(np.arange(0, 360, 5.0))
    fast = audit(d4, AuditSettings(angles=angles, sections=d4.sections(1), refine=False))
    assert fast.min_clearance == pytest.approx(brute_force_min(d4, angles, None), abs=1e-11)


def test_odd_tooth_counts_interleave_the_waves(d1):
    # 201/203: the waves are offset by half a pitch; folding still holds (docs/models.md 7)
    odd = build_drive(with_changes(d1.design, drive={"z_flex": 201, "z_rigid": 203}))
    angles = np.deg2rad(np.arange(0, 360, 4.0))
    fast = audit(odd, AuditSettings(angles=angles, sections=odd.sections(2), refine=False))
    assert fast.min_clearance == pytest.approx(brute_force_min(odd, angles, odd.sections(2)), abs=1e-11)

    # at one generator angle the two waves hold the same tooth angles with even counts
    # (the fold halves them) and interleaved ones with odd counts (nothing merges)
    def unique(drive, waves):
        r = audit(
            drive,
            AuditSettings(
                angles=np.array([0.1]), sections=drive.sections(1), use_waves=waves, use_mirror=False, refine=False
            ),
        )
        return r.counts["unique_tooth_angles"]

    assert unique(odd, True) == unique(odd, False) == 201
    assert unique(d1, True) * 2 == unique(d1, False) == 200


def test_deliberately_interfering_design_is_found_where_and_how_deep(d4):
    # W0 = 1.6 m pushes the flexspline tip 140 um into the rigid root on the major axis:
    # r_fb - r_ag - W0 = 18.4 - 17.9 - 0.64 (closed form, D4 radii)
    bad = build_drive(with_changes(d4.design, generator={"w0_coef": 1.6}))
    radial = bad.rigid.r_f - bad.flex.r_a - bad.law.w0
    assert radial == pytest.approx(-0.140, abs=1e-12)
    scene = Scene(bad)
    at_axis = tooth_clearance(scene, np.array([0.0])).min[0]
    # the deepest vertex is the tip corner, measured to the root arc: the radial overlap,
    # within the chord tolerance of the polygons (1 um)
    assert at_axis == pytest.approx(radial, abs=1e-3)
    res = _audit(bad, 1.0, 1)
    assert res.interference and res.min_clearance <= at_axis
    assert abs(audit_json(res)["worst"]["tooth_angle_deg"]) < 10.0  # near the major axis
    clean = _audit(d4, 1.0, 1)
    assert not clean.interference and clean.min_clearance > 0


def test_d1_cycloidal_entry_gap_much_larger_than_involute():
    # [S1]: the cycloidal teeth enter with a larger gap than the involute ones (at no load twice; under
    # [S1]'s 900 N m several times: tests/test_source_drives.py), smallest at the inner end of the rim
    res = {}
    for name in ("d1_involute", "d1_cycloidal"):
        drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
        res[name] = _audit(drive, 30.0, 3)
    inv, cyc = res["d1_involute"].entry_gap, res["d1_cycloidal"].entry_gap
    assert 0 < inv < cyc and cyc > 1.5 * inv
    for r in res.values():
        assert audit_json(r)["entry"]["section_z_mm"] == pytest.approx(30.0)


def test_crossing_is_where_the_tip_meets_the_rigid_tip_circle_and_delta_is_the_pinch():
    # the teaching template's nominal teeth pinch just after they cross (docs/models.md 5): the crossing is
    # exact, Delta is the pinch, no larger than the crossing's gap
    d1n = build_drive(load_design(TEMPLATES / "d1_involute_nominal.toml"))
    scene = Scene(d1n)
    res = _audit(d1n, 30.0, 3, refine=True)
    cr = res.findings["entry_crossing"]
    phi, z = cr.tooth_angle, cr.section_z
    rot, shift = scene.pose(np.array([phi]), z)
    # at the crossing the outermost point of the tip arc is on the rigid tip circle; checked on
    # a dense sampling of the arc (1e5 points: sagitta 1e-9 mm); the crossing is closed to ~1e-10 rad
    # and points move < 3 mm/rad
    arc = scene.tip_arc
    p = arc.point(np.linspace(arc.t0, arc.t1, 100001))
    c, s = np.cos(rot[0]), np.sin(rot[0])
    placed = p @ np.array([[c, s], [-s, c]]) + shift[0]
    assert np.hypot(placed[:, 0], placed[:, 1]).max() == pytest.approx(d1n.rigid.r_a, abs=1e-7)
    assert tooth_clearance(scene, np.array([phi]), z, exact=True).min[0] == pytest.approx(cr.value, abs=1e-7)
    e = audit_json(res)["entry"]
    assert e["kind"] == "pinch" and res.entry_gap <= cr.value
    assert res.entry_gap == res.findings["entry_pinch"].value
    # the pinch is no higher than the polygons' smallest clearance near it less their
    # difference from the curves (2 x chord tolerance per pair), plus the JSON rounding (1e-4 um)
    pphi = np.deg2rad(e["pinch_tooth_angle_deg"])
    near = np.linspace(pphi - np.deg2rad(1), pphi + np.deg2rad(1), 401)
    pz = e["pinch_section_z_mm"]
    assert e["pinch_um"] <= 1e3 * tooth_clearance(scene, near, pz).min.min() + 1e3 * scene.chord_gap + 1e-4


def test_backlash_of_a_clean_design_by_rotation(d4):
    # turning the flexspline by the reported dead travel each way brings a tooth into contact
    from wgcad.clearance.engine import backlash

    scene = Scene(d4)
    total = backlash(scene, 0.0)
    assert total > 0
    # turn every tooth by +-total: one side alone must already interfere somewhere
    k = np.arange(86)
    mat = 2 * pi * k / 86
    for sgn in (1, -1):
        rot, shift = tooth_pose(d4.law, mat, d4.r_m, frame_angle=0.0)
        c, s = np.cos(sgn * total), np.sin(sgn * total)
        sh = np.stack([c * shift[:, 0] - s * shift[:, 1], s * shift[:, 0] + c * shift[:, 1]], axis=1)
        lo, up, _ = scene.neighbours(sh, rot + sgn * total)
        d = np.minimum(scene.clearance_to(rot + sgn * total, sh, lo), scene.clearance_to(rot + sgn * total, sh, up))
        assert d.min() < 0


def test_interfering_backlash_is_undefined():
    res = _audit(build_drive(load_design(TEMPLATES / "d1_involute_nominal.toml")), 30.0, 3)
    assert res.interference and audit_json(res)["backlash_arcmin"] is None


def test_worst_spot_is_canonical_whatever_the_shortcuts(d1):
    # issue 13: default D1 reported the non-working flank of one tooth at +5.16 deg and
    # --no-shortcuts the working flank of another at +174.84 deg (mirror images, equal depth):
    # the spot is now folded to the nearest major axis and reported with its mirror image
    fast = _audit(d1, 3.0, 3)
    full = _audit(d1, 3.0, 3, **{s: False for s in SHORTCUTS})
    for key in ("tooth_angle_deg", "location", "mirror", "section_z_mm", "tooth", "generator_angle_deg"):
        assert audit_json(fast)["worst"][key] == audit_json(full)["worst"][key], key
    assert (
        audit_json(fast)["worst"]["tooth_angle_deg"] >= 0 and abs(audit_json(fast)["worst"]["tooth_angle_deg"]) <= 90.0
    )
    assert audit_json(fast)["worst"]["mirror"]["tooth_angle_deg"] == -audit_json(fast)["worst"]["tooth_angle_deg"]
    flanks = {"working flank", "non-working flank"}
    if audit_json(fast)["worst"]["location"] in flanks:
        assert {audit_json(fast)["worst"]["location"], audit_json(fast)["worst"]["mirror"]["location"]} == flanks


def test_pinch_is_found_beyond_six_degrees_of_the_crossing():
    # issue 13, D3 as first templated (textbook teeth): the working-flank clearance falls to about -150 um
    # 7.2 deg after the crossing, outside the old fixed 6 deg window ("entry pinch: none")
    d3 = build_drive(
        with_changes(
            load_design(TEMPLATES / "d3_external.toml"), tooth={"addendum_coef": 1.0}, flexspline={"thinning": 0.0}
        )
    )
    res = _audit(d3, 30.0, 1)
    e = audit_json(res)["entry"]
    assert e["pinch_um"] is not None and e["pinch_um"] < -100.0
    assert abs(e["pinch_tooth_angle_deg"] - e["crossing_tooth_angle_deg"]) > 6.0
    # the pinch is a sample of the clearance: the audit's minimum holds it (issue 19: -150.546 vs -150.520)
    assert res.min_clearance <= e["pinch_um"] * 1e-3 + 1e-7  # + the JSON's rounding to 1e-4 um


def test_pinch_is_looked_for_only_where_the_tips_pass():
    # issue 19, D2 as first templated (textbook teeth): the flanks wedge near the major axis (-82 um at
    # +7.9 deg); that is not the entry. The entry's dip is where the tip corners pass each other, ~67 deg
    d2 = build_drive(
        with_changes(
            load_design(TEMPLATES / "d2.toml"),
            tooth={"addendum_coef": 1.0},
            flexspline={"thinning": 0.0},
            drive={"rotation": "ccw"},
            generator={"w0_coef": 1.2},
        )
    )
    res = _audit(d2, 30.0, 3)
    e = audit_json(res)["entry"]
    assert res.min_clearance < -0.08
    assert e["pinch_tooth_angle_deg"] > 60.0 and e["pinch_um"] > 0, e
    assert res.entry_gap > 0


def test_progress_moves_with_the_work(d1):
    # issue 13: fine-grained fractions of the actual work, not six fixed stages at the end
    calls = []
    angles = np.deg2rad(np.arange(0, 360, 0.5))
    audit(
        d1,
        AuditSettings(angles=angles, sections=d1.sections(3), refine=False),
        progress=lambda d, t, s: calls.append((d, t, s)),
    )
    done = [d / t for d, t, _ in calls]
    assert done == sorted(done) and done[-1] == 1.0
    assert len(calls) >= 10 and len({round(x, 3) for x in done}) >= 8
    stages = [s for _, _, s in calls]
    assert stages.index("entry gap") > stages.index("clearance")


def test_pair_distance_on_two_threads_equals_shapely(monkeypatch):
    """The split across the helper thread gives shapely's own figures, pair for pair, in order; an error in the
    helper's half reaches the caller."""
    import wgcad.clearance.distance as dist

    rng = np.random.default_rng(5)
    n = 1001
    t = np.linspace(0, 2 * np.pi, 27, endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)]
    a = shapely.polygons(ring[None] * rng.uniform(0.5, 1, (n, 1, 1)) + rng.normal(0, 2, (n, 1, 2)))
    b = shapely.polygons(ring[None] * rng.uniform(0.5, 1, (n, 1, 1)) + rng.normal(0, 2, (n, 1, 2)))
    from wgcad.clearance import threads

    monkeypatch.setattr(threads, "CORES", 2)
    got = dist.pair_distance(a, b)
    np.testing.assert_array_equal(got, shapely.distance(a, b))
    assert (got == 0).any() and (got > 0).any()
    np.testing.assert_array_equal(dist.pair_distance(a, b[0]), shapely.distance(a, b[0]))  # one against many
    with pytest.raises(TypeError):
        dist.pair_distance(np.array([1.0] * n, dtype=object), b)


def test_halves_on_the_helper_return_raise_and_never_wait_on_themselves(monkeypatch):
    """Both halves' values reach the caller in order, an exception in the helper's half is raised there; in_halves
    called on the helper thread itself measures both halves there (queued, it would wait on itself for ever)."""
    import threading

    from wgcad.clearance import threads

    monkeypatch.setattr(threads, "CORES", 2)
    x = np.arange(10.0)
    np.testing.assert_array_equal(threads.in_halves(np.negative, (x,), least=2), -x)
    with pytest.raises(ZeroDivisionError):
        threads.in_halves(lambda a: [1 / int(v) for v in a], (x,), least=2)
    out = []
    nested = lambda: threads.pool().submit(threads.in_halves, np.negative, (x,), (), 2).result()  # noqa: E731
    waiter = threading.Thread(target=lambda: out.append(nested()), daemon=True)
    waiter.start()
    waiter.join(10)
    assert len(out) == 1, "a nested split waited on the helper for ever"
    np.testing.assert_array_equal(out[0], -x)


def test_a_conjugate_space_deeper_than_its_root_circle_keeps_a_valid_tooth(tmp_path):
    """Fuzz finding (seed 2078): D1 conjugate without the rigid gear's shift generates a tooth space 2.25 mm beyond
    the nominal root circle; the tooth polygon's closure through the body then crossed the period and the audit
    stopped with an internal error (GEOS TopologyException). The closure lies beyond the period's deepest point now:
    a valid polygon, and the audit reports the interference (exit 1)."""
    import shapely

    from wgcad.cli import main

    path = tmp_path / "d1c.toml"
    path.write_text(edit_toml((TEMPLATES / "d1_conjugate.toml").read_text(), "rigid", "shift", None))
    drive = build_drive(load_design(path))
    r = np.hypot(*drive.rigid.period.T)
    assert r.max() > drive.rigid.r_f + 2.0  # the premise: the space runs deeper than the root circle
    for gear in (drive.flex, drive.rigid):
        assert shapely.Polygon(gear.tooth_polygon()).is_valid
    assert main(["audit", str(path), "--quiet", "--step-deg", "4", "--no-refine"]) == 1
