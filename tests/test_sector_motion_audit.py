"""Motion law of the discrete-motion drive against a hand count, and the sectored audit: tip-to-tip with full teeth, none with variable heights."""

from math import pi

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.design.sectors import SectorsSpec
from wgcad.drive import build_drive, tooth_spec
from wgcad.kinematics import flex_rotation
from wgcad.profiles.sector import SectorLayout, TeethByHeight, sector_layout
from wgcad.sector import SectoredScene, motion_law, sectored_audit, simulated_heights
from wgcad.sector.scene import sweep_angles


def _deg(x):
    return float(np.rad2deg(x))


def test_motion_law_hand_count_d4():
    """D4: flexspline 84 teeth; coupling sectors 21 teeth at 360/84 deg, transmission sectors 22 teeth at 360/88 deg.

    Hand count: the output stands while the major axis goes from the first to the last space between two coupling
    teeth: 21 teeth -> 20 such spaces -> 19 pitches of 360/84 = 81.428571 deg. The rest of the half turn, 180 - 81.428571
    = 98.571429 deg, moves it: the 86 rigid spaces of a turn meet 86 successive flexspline teeth, 2 more than its 84, so
    it turns back by 2 teeth = 2 x 360/84 = 8.571429 deg per turn, one tooth per move. Inside a transmission sector the
    space pitch is 360/88 against 360/84: u = p_t / (p_t - p_g) = 84 / (84 - 88) = -21; the spaces next to a joint are
    (3 p_g + p_t)/4 and (p_g + 3 p_t)/4 apart (each tooth owns its own pitch), giving u = (3*88 + 84)/(84 - 88) = -87
    and (88 + 3*84)/(3 (84 - 88)) = -28.333.
    """
    d = load_design(TEMPLATES / "d4_sectored.toml")
    lay = sector_layout(d.sectors, 84, 88)
    law = motion_law(lay, 84)
    runs = law.runs()
    dwells = [r for r in runs if r.kind == "dwell"]
    moves = [r for r in runs if r.kind == "move"]
    assert len(dwells) == 2 and len(moves) == 2
    for r in dwells:
        assert _deg(r.length) == pytest.approx(19 * 360 / 84, abs=1e-9)
    for r in moves:
        assert _deg(r.length) == pytest.approx(180 - 19 * 360 / 84, abs=1e-9)
        assert _deg(r.output_step) == pytest.approx(-360 / 84, abs=1e-9)
    assert _deg(law.advance) == pytest.approx(-2 * 360 / 84, abs=1e-9)
    ratios = sorted({round(p.ratio, 6) for p in law.phases() if p.kind == "move"})
    assert ratios == pytest.approx(sorted([-21.0, -87.0, -340 / 12]), abs=1e-6)
    # the long move piece: 21 space-to-space steps inside the 22-tooth transmission sector... 20 steps of 360/88
    main = [p for p in law.phases() if p.kind == "move" and abs(p.ratio + 21) < 1e-6]
    assert _deg(main[0].length) == pytest.approx(20 * 360 / 88, abs=1e-9)
    # the output stands still in the dwell, and a half turn later it has moved one tooth back
    a = np.deg2rad(np.linspace(10, 80, 50))
    assert np.ptp(law(a)) < 1e-15
    assert np.allclose(law(a + pi) - law(a), -2 * pi / 84, atol=1e-15)


def test_motion_law_of_a_plain_gear_is_the_gear_ratio():
    """A layout of one kind at the pitch of a plain 88-tooth gear: the law must be phi_h / u_hg (wgcad.kinematics)."""
    z_b, z_g = 88, 84
    c = (np.arange(z_b) + 0.5) * 2 * pi / z_b
    lay = SectorLayout(
        c,
        np.zeros(z_b, int),
        np.arange(z_b),
        np.zeros(z_b, bool),
        np.full(z_b, 2 * pi / z_b),
        np.zeros(z_b),
        np.array([0.0, 2 * pi]),
        ("transmission",),
        c + pi / z_b,
    )
    law = motion_law(lay, z_g)
    phi_h = np.linspace(-3.0, 9.0, 1001)
    expect = flex_rotation(phi_h, z_g, z_b)
    g = law(phi_h)
    # same law up to a constant (the tooth that sits in the first space): whole flexspline pitches
    off = (g - expect)[0]
    assert np.allclose(g - expect, off, atol=1e-12)
    n = off / (2 * pi / z_g)
    assert abs(n - round(n)) < 1e-9


def test_motion_law_hand_count_86_tooth_flexspline():
    """A layout for the printed 86-tooth flexspline: coupling 21 teeth at 360/86, transmission 23 teeth at
    (22/23) 360/86 (a sector of 22 flexspline pitches). Dwell 19 x 360/86 deg; 2 x (21 + 23) = 88 rigid teeth -> one
    tooth (360/86 deg) back per move; inside a transmission sector u = p_t/(p_t - p_g) = 22/(22 - 23) = -22."""
    sp = SectorsSpec(kinds=("coupling", "transmission") * 2, teeth=(21, 23, 21, 23), pitch_z=(86.0, 86 * 23 / 22) * 2)
    law = motion_law(sector_layout(sp, 86, 88), 86)
    runs = law.runs()
    assert [r.kind for r in runs].count("dwell") == 2
    for r in runs:
        if r.kind == "dwell":
            assert _deg(r.length) == pytest.approx(19 * 360 / 86, abs=1e-9)
        else:
            assert _deg(r.output_step) == pytest.approx(-360 / 86, abs=1e-9)
    assert any(abs(p.ratio + 22) < 1e-6 for p in law.phases())


@pytest.fixture(scope="module")
def d4():
    design = load_design(TEMPLATES / "d4_sectored.toml")
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    teeth = TeethByHeight(tooth_spec(design, "rigid"), drive.rigid)
    return design, drive, lay, teeth


@pytest.fixture(scope="module")
def d4_deep():
    """D4 read with W0 = 2 m, the transmission sectors' own wave (the template as first written)."""
    import tomllib

    from conftest import edit_toml

    from wgcad.design import parse_design

    text = edit_toml((TEMPLATES / "d4_sectored.toml").read_text(), "generator", "w0_coef", "2.0")
    design = parse_design(tomllib.loads(text))
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    return design, drive, lay, TeethByHeight(tooth_spec(design, "rigid"), drive.rigid)


def test_the_template_runs_over_the_whole_cycle_with_its_heights_and_with_full_teeth(d4):
    """W0 = 1.46 m: no tip-to-tip contact and no flank interference anywhere in the cycle, with [S5]'s heights and with
    full teeth alike (0.2 deg steps: a grid other than the heights' or the CLI's)."""
    from wgcad.sector.built import built_gear

    design, drive, lay, teeth = d4
    built = built_gear(design, drive=drive)["built"]
    for h in (built, np.full(lay.n_teeth, teeth.height)):
        a = sectored_audit(SectoredScene(drive, lay, teeth, h), step_deg=0.2)
        assert not a.interferes and not a.has_tip_to_tip
        assert a.min_clearance > 0.002  # 4.1 um at these steps: two chord tolerances clear of the curves' figure
        assert a.counts["facing_pairs"] > 100  # out-of-register tips were there and measured


def test_deep_wave_jams_every_coupling_tooth_not_only_at_the_boundaries(d4_deep):
    """W0 = 2 m, full teeth: every coupling tooth meets a flexspline tip tip to tip (the middle ones too: the coupling's
    own wave, tests/test_sector_heights.py), and the transmission sectors only at their joint teeth."""
    design, drive, lay, teeth = d4_deep
    a = sectored_audit(SectoredScene(drive, lay, teeth, np.full(lay.n_teeth, teeth.height)), step_deg=0.5)
    assert a.has_tip_to_tip
    hit = {(x.sector, x.tooth_in_sector) for x in a.tip_to_tip}
    for s, kind in enumerate(lay.kinds):
        z = design.sectors.teeth[s]
        if kind == "coupling":
            assert all((s, k) in hit for k in range(z))
        else:
            assert (s, 0) in hit and (s, z - 1) in hit
            assert not any((s, k) in hit for k in range(1, z - 1))
    assert a.min_tip_clearance < -0.05  # about -98 um: a real jam, not a contact at the tolerance
    assert a.min_flank_clearance < -0.1  # and -127 um at the coupling's flanks, 23.6 deg from the axis


def test_deep_wave_simulated_heights_remove_tip_to_tip_not_the_flank_interference(d4_deep):
    """Heights found on a 0.25 deg sweep, audited on a different (0.2 deg) sweep: no tip-to-tip anywhere in the cycle,
    but the coupling flanks still interfere: lowering tips cannot remove what the flanks meet."""
    design, drive, lay, teeth = d4_deep
    sim = simulated_heights(drive, lay, teeth, 0.010, step_deg=0.25)
    a = sectored_audit(SectoredScene(drive, lay, teeth, sim.heights), step_deg=0.2)
    assert not a.has_tip_to_tip, a.tip_to_tip[:3]
    assert a.min_tip_clearance > 0.005  # the 10 um asked for, less the sampling error of 0.25 deg steps (~3.5 um)
    assert a.flank_interference and a.min_flank_clearance < -0.1 and a.worst.sector_kind == "coupling"


def test_half_turn_symmetry_shortcut(d4):
    """Identical waves: the scene at phi_h + pi is the one at phi_h turned by pi (same pairs, same clearances)."""
    design, drive, lay, teeth = d4
    sc = SectoredScene(drive, lay, teeth, np.full(lay.n_teeth, teeth.height))
    a = np.deg2rad(np.array([3.0, 47.5, 91.0, 133.3]))
    p1, p2 = sc.pairs(a), sc.pairs(a + pi)
    c1, c2 = sc.clearance(p1), sc.clearance(p2)
    # rigid tooth i and i + 43 are a half turn apart; pair by (angle, rigid tooth) and compare
    d1 = {(int(a), int(r) % 43, int(f) % 42): c for a, r, f, c in zip(p1.angle, p1.rigid, p1.flex, c1)}
    d2 = {(int(a), int(r) % 43, int(f - 1) % 42): c for a, r, f, c in zip(p2.angle, p2.rigid, p2.flex, c2)}
    assert d1.keys() == d2.keys() and len(d1) > 100
    assert max(abs(d1[k] - d2[k]) for k in d1) < 1e-9


def test_sweep_covers_half_turn():
    a = sweep_angles(0.25)
    assert len(a) == 720 and a[0] == 0.0 and a[-1] < pi


def test_third_tooth_shortcut_changes_nothing(d4, monkeypatch):
    """Measuring the third-nearest rigid tooth only where the flexspline tooth can reach it gives the full answer."""
    import wgcad.sector.scene as scene_mod

    design, drive, lay, teeth = d4
    for h in (np.full(lay.n_teeth, teeth.height), np.where(lay.coupling, 0.45, teeth.height)):
        a = sectored_audit(SectoredScene(drive, lay, teeth, h), step_deg=1.0)
        monkeypatch.setattr(scene_mod, "THIRD_TOOTH_WITHIN", 1.0)  # every pair gets its third tooth
        b = sectored_audit(SectoredScene(drive, lay, teeth, h), step_deg=1.0)
        monkeypatch.undo()
        assert b.counts["pairs_measured"] > 1.3 * a.counts["pairs_measured"]
        assert a.min_clearance == b.min_clearance and a.min_tip_clearance == b.min_tip_clearance
        assert np.array_equal(a.per_tooth_tip, b.per_tooth_tip)


def test_transmission_sector_is_the_plain_drive(d4):
    """With the major axis deep in a transmission sector, the sectored scene (motion law, sector layout, pairs) must give
    what the plain clearance engine gives for the plain 84/88 drive at the plain gear ratio: a transmission sector is a
    quarter of the 88-tooth gear, and the motion law there is phi_h / u_hg up to whole flexspline pitches."""
    from wgcad.clearance.engine import Scene, clearance_at_poses

    design, drive, lay, teeth = d4
    sc = SectoredScene(drive, lay, teeth, np.full(lay.n_teeth, teeth.height))
    plain = Scene(drive)
    for phi_h_deg in (120.0, 135.0, 150.0, 315.0):
        phi_h = np.deg2rad(phi_h_deg)
        d = sc.motion(phi_h) - flex_rotation(phi_h, 84, 88)
        assert abs(d / (2 * pi / 84) - round(d / (2 * pi / 84))) < 1e-9
        p = sc.pairs(np.array([phi_h]))
        near = np.abs(p.phi) < np.deg2rad(25.0)  # the rigid teeth around them are all transmission teeth
        p = p.take(near)
        c = sc.clearance(p)
        mine = {}
        for k, v in zip(p.flex, c):
            mine[int(k)] = min(mine.get(int(k), np.inf), v)
        ks = np.array(sorted(mine))
        rot, shift, _ = sc.flex_state(np.array([phi_h]))
        ref = clearance_at_poses(plain, rot[0, ks], shift[0, ks]).min
        assert len(ks) > 8
        assert np.allclose([mine[k] for k in ks], ref, rtol=0, atol=1e-12)
