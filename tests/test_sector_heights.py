"""Variable tooth heights of the sectored rigid gear (docs/models.md 2.3): [S5]'s formula as built, against an
independent reimplementation of [S5]'s text; where its lowered teeth lie; the other rules beside it; the record of how
every tooth got its height."""

import tomllib
from math import cos, pi, sin

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.design import load_design, parse_design
from wgcad.drive import build_drive, tooth_spec
from wgcad.placement import tooth_pose, transform
from wgcad.profiles.sector import TeethByHeight, sector_layout, sectored_outline
from wgcad.sector import SectoredScene, closed_form_heights, motion_law, sectored_audit, simulated_heights
from wgcad.sector.built import built_gear
from wgcad.sector.provenance import height_records

STEP_DEG = 0.25  # sweep step of these tests (the CLI default is 0.1)
C_REQ = 0.010  # tip clearance of the template, mm
D4 = TEMPLATES / "d4_sectored.toml"


def _parts(design):
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    return drive, lay, TeethByHeight(tooth_spec(design, "rigid"), drive.rigid)


@pytest.fixture(scope="module")
def d4():
    design = load_design(D4)
    drive, lay, teeth = _parts(design)
    return {
        "design": design,
        "drive": drive,
        "layout": lay,
        "teeth": teeth,
        "gear": built_gear(design),
        "boundary": closed_form_heights(drive, lay, teeth, assign="boundary"),
        "register": closed_form_heights(drive, lay, teeth, assign="register", step_deg=STEP_DEG),
        "sim": simulated_heights(drive, lay, teeth, C_REQ, step_deg=STEP_DEG),
    }


def _coupling_sectors(lay):
    return [lay.coupling_sector_teeth(s) for s in range(len(lay.kinds)) if lay.kinds[s] == "coupling"]


def _patent_heights_from_the_text(toml: dict) -> list:
    """[S5], claim 2, written out from the patent's text and the design file's numbers alone (no wgcad):
    h_i = r_fix - r_ari, r_ari = r_cr + w(phi_h) + h_s, w(phi_h) = w0/(A - B) (A cos(phi_h) - B),
    A = pi/2 - sin(beta) cos(beta) - beta, B = -2 sin(beta) + (4 beta/pi) sin(beta) + (4/pi) cos(beta);
    r_fix the rigid root circle, r_cr the undeformed neutral line, h_s from it to the flexspline tip; phi_h read as
    [S5] fig. 3 draws it, the wave's major axis on the boundary line, so that a tooth's phi_h is its angle from the
    boundary; at most the full height. Tooth data as textbook involute gears of the template's coefficients
    (internal rigid gear: root at m (z/2 + h_a* + c* + x)); the sectors' teeth at their pitch, each owning one pitch."""
    dr, to, fl, ri, ge, se = (toml[k] for k in ("drive", "tooth", "flexspline", "rigid", "generator", "sectors"))
    m, zg, zb = dr["module"], dr["z_flex"], dr["z_rigid"]
    ha, c = to["addendum_coef"], to["clearance_coef"]
    r_fix = m * (zb / 2 + ha + c + ri["shift"])
    r_tip_flex = m * (zg / 2 + ha + fl["shift"])
    r_root_flex = m * (zg / 2 - ha - c + fl["shift"])
    r_cr = r_root_flex - fl["rim_thickness"] / 2
    h_s = r_tip_flex - r_cr
    full = m * (2 * ha + c)
    beta = ge["beta_deg"] * pi / 180
    w0 = ge["w0_coef"] * m
    A = pi / 2 - sin(beta) * cos(beta) - beta
    B = -2 * sin(beta) + 4 * beta / pi * sin(beta) + 4 / pi * cos(beta)
    z_c = se["teeth"][0]  # the first sector is a coupling sector, at the flexspline's pitch
    out = []
    for i in range(z_c):
        phi_h = min(i + 0.5, z_c - i - 0.5) * 2 * pi / zg  # the tooth's angle from the nearer boundary
        w = w0 / (A - B) * (A * cos(phi_h) - B)
        out.append(min(full, r_fix - (r_cr + w + h_s)))
    return out


def test_built_heights_equal_the_patents_formula_written_from_its_text(d4):
    toml = tomllib.loads(D4.read_text())
    assert toml["sectors"]["heights"] == "closed_form" and toml["sectors"]["assign"] == "boundary"
    ref = np.array(_patent_heights_from_the_text(toml))
    built = d4["gear"]["built"]
    for s in _coupling_sectors(d4["layout"]):
        # 1 um: [S5] writes w on the disc (|phi| <= beta); the code takes the disc law of docs/models.md 3.3, whose
        # free span past beta = 30 deg differs from that expression by 0.05 um at the last lowered tooth (32.1 deg)
        # and reaches the full height before it differs more
        np.testing.assert_allclose(built[s], ref, rtol=0, atol=1e-3)
    assert np.abs(built[d4["layout"].coupling_sector_teeth()] - ref).max() < 1e-4
    # the transmission sectors keep their full teeth
    assert np.all(built[~d4["layout"].coupling] == d4["teeth"].height)


def test_lowered_only_in_local_regions_about_the_boundaries(d4):
    """[S5] claim 1: variable heights "in local regions about the boundary lines": every lowered tooth lies nearer a
    boundary than the angle where w falls to the tip gap of the undeformed teeth; the teeth in the middle of a coupling
    sector keep the full height, and the heights rise from each boundary toward the middle."""
    lay, H, drive = d4["layout"], d4["teeth"].height, d4["drive"]
    cf = d4["boundary"]
    gap = cf.r_fix - H - cf.r_cr - cf.h_s
    phi = np.linspace(0, pi / 2, 200001)
    reach = phi[np.argmax(drive.law.state(phi).w <= gap)]  # w falls monotonically from the axis
    # the same reach from [S5]'s text alone: w0/(A - B) (A cos phi - B) = gap, the template's numbers (the gap of
    # its textbook teeth, 0.2 mm, as _patent_heights_from_the_text reads them)
    toml = tomllib.loads(D4.read_text())
    beta, w0 = toml["generator"]["beta_deg"] * pi / 180, toml["generator"]["w0_coef"] * toml["drive"]["module"]
    A = pi / 2 - sin(beta) * cos(beta) - beta
    B = -2 * sin(beta) + 4 * beta / pi * sin(beta) + 4 / pi * cos(beta)
    reach_s5 = np.arccos((0.2 * (A - B) / w0 + B) / A)
    assert gap == pytest.approx(0.2, abs=1e-12)
    built = d4["gear"]["built"]
    for s in _coupling_sectors(lay):
        h = built[s]
        low = h < H - 1e-9
        assert np.array_equal(low, lay.delta[s] < reach)
        assert np.array_equal(low, lay.delta[s] < reach_s5)  # 36.0 deg: between the 8th tooth (32.1) and 9th (36.4)
        mid = len(h) // 2
        assert not low[mid - 2 : mid + 3].any()  # the five middle teeth of the 21 at full height
        assert low[:8].all() and low[-8:].all()
        half = h[: mid + 1]
        assert np.all(np.diff(half)[: int(low[: mid + 1].sum())] > 0)
        assert h[0] < 0.5 * H  # next to the boundary the wave pushes the tip far in


@pytest.mark.parametrize("method,tol", [("boundary", 1e-12), ("register", 1e-9), ("sim", 1e-4)])
def test_heights_symmetric_about_sector_middle_and_equal_between_sectors(d4, method, tol):
    # the sweep grid (k * STEP_DEG) is symmetric about the sector middles (45 and 225 deg), so mirrored teeth see mirrored
    # samples: equal to rounding (closed forms) or to the bisection tolerance 0.1 um (simulation); no symmetry is assumed
    h = d4[method].heights
    a, b = _coupling_sectors(d4["layout"])
    assert np.allclose(h[a], h[a][::-1], rtol=0, atol=tol)
    assert np.allclose(h[a], h[b], rtol=0, atol=tol)


@pytest.mark.parametrize("method", ["boundary", "register", "sim"])
def test_heights_never_above_full_and_positive(d4, method):
    h = d4[method].heights
    H = d4["teeth"].height
    assert np.all(h <= H + 1e-12) and np.all(h > 0)
    assert abs(H - 0.7) < 1e-12  # m (2 h_a* + c*) = 0.4 (1.5 + 0.25)


def test_closed_form_parameters_explicit(d4):
    cf, drive = d4["boundary"], d4["drive"]
    assert cf.r_fix == pytest.approx(drive.rigid.r_f) == pytest.approx(18.4)
    assert cf.r_cr == pytest.approx(drive.r_m) == pytest.approx(16.55)
    assert cf.h_s == pytest.approx(drive.flex.r_a - drive.r_m) == pytest.approx(0.95)
    assert cf.w0 == pytest.approx(1.46 * 0.4) and cf.beta == pytest.approx(np.deg2rad(30.0))


def test_closed_form_is_the_deformed_tip_radius(d4):
    """r_ari = r_cr + w + h_s against the radius of the placed flexspline tooth's tip centre (tooth_pose, exact placement):
    they differ only by the tangential terms, (v + h_s theta)^2 / (2 r) to first order."""
    cf, drive = d4["boundary"], d4["drive"]
    i = np.nonzero(np.isfinite(cf.phi))[0]
    phi = cf.phi[i]
    rot, shift = tooth_pose(drive.law, phi, drive.r_m)
    tip = transform(np.array([[drive.flex.r_a, 0.0]]), rot, shift)[:, 0, :]
    r_exact = np.hypot(tip[:, 0], tip[:, 1])
    r_form = cf.r_fix - cf.heights[i]
    st = drive.law.state(phi)
    bound = (np.abs(st.v) + cf.h_s * np.abs(st.theta)) ** 2 / (2 * drive.r_m) + 1e-9
    low = cf.heights[i] < d4["teeth"].height - 1e-12
    assert low.sum() == 32
    assert np.all(np.abs(r_exact - r_form)[low] <= bound[low])


def test_no_coupling_tooth_of_the_template_needs_lowering_in_the_sweep(d4):
    """With W0 = 1.46 m the swept cycle finds no flexspline tip facing a coupling tooth closer than the 10 um asked: the
    simulated and the register rule keep every coupling tooth full (the mid-sector lowering of W0 = 2 m, below, is
    gone). Only the transmission sectors' tips, where they leave the mesh 35 deg from the axis 8.6 um apart, ask the
    simulated rule for 1.3 um at most."""
    lay, H = d4["layout"], d4["teeth"].height
    for rule in ("sim", "register"):
        h = d4[rule].heights
        assert np.all(h[lay.coupling] == H)
        assert np.all(h >= H - 1.3e-3)


def test_why_the_deep_wave_lowered_every_coupling_tooth():
    """The reading W0 = 2 m (the transmission sectors' own wave, docs/models.md 9 as first templated) lowers every
    coupling tooth, the middle ones too. Not from the sector counts: the motion law moves the flexspline by exactly one
    pitch a move, so it stands in register with the next coupling sector. From the coupling's own wave: a flexspline
    tip faces a coupling tip while it still reaches past the rigid tip circle, about 32 deg from the major axis with
    the axis inside the sector, which no rule of the boundary (axis on a boundary) sees."""
    text = edit_toml(D4.read_text(), "generator", "w0_coef", "2.0")
    design = parse_design(tomllib.loads(text))
    drive, lay, teeth = _parts(design)
    law = motion_law(lay, design.drive.z_flex)
    moves = [r for r in law.runs() if r.kind == "move"]
    assert all(abs(r.output_step + 2 * pi / 84) < 1e-12 for r in moves)  # register after a move: exact
    H = teeth.height
    a = sectored_audit(SectoredScene(drive, lay, teeth, np.full(lay.n_teeth, H)), step_deg=0.5)
    mid = lay.coupling_sector_teeth()[10]
    hits = [x for x in a.tip_to_tip if x.rigid_tooth == mid]
    assert hits, "the middle coupling tooth meets a flexspline tip tip to tip"
    x = hits[0]
    # the major axis inside the coupling sector (0..90 deg), the facing tooth ~32 deg from it
    assert 0.0 < np.rad2deg(x.generator_angle) % 180.0 < 90.0
    assert 25.0 < abs(np.rad2deg(x.flex_tooth_angle)) < 40.0
    reg = closed_form_heights(drive, lay, teeth, assign="register", step_deg=0.5)
    cs = lay.coupling_sector_teeth()
    assert np.all(reg.heights[cs] < H - 0.1)  # every coupling tooth, the middle ones too, lowered by > 0.1 mm
    assert np.all(np.abs(np.rad2deg(reg.phi[cs])) > 25.0)


def test_outline_tips_at_the_built_heights(d4):
    lay, teeth = d4["layout"], d4["teeth"]
    h = d4["gear"]["built"]
    out = sectored_outline(lay, teeth, h)
    R = np.hypot(out[:, 0], out[:, 1])
    a = np.arctan2(out[:, 1], out[:, 0])
    for i in range(lay.n_teeth):
        near = np.abs((a - lay.centres[i] + pi) % (2 * pi) - pi) < 0.25 * lay.pitch[i]
        # the tip land of an internal tooth is its innermost arc: r_f - h, to the 1 um chord tolerance
        assert R[near].min() == pytest.approx(teeth.full.r_f - h[i], abs=1e-9)


def test_every_tooth_records_how_its_height_was_set(d4):
    """The record of each tooth: the rule, the generator angle (the nearer boundary), the flexspline tooth facing it
    there (the nearest to it, found here by placing every tooth), the formula's terms, and the smallest clearance it
    keeps over the audited cycle (the audit's, tooth by tooth)."""
    gear, lay, drive = d4["gear"], d4["layout"], d4["drive"]
    audit = sectored_audit(SectoredScene(drive, lay, d4["teeth"], gear["built"]), step_deg=1.0)
    recs = height_records(gear, audit)
    assert len(recs) == lay.n_teeth
    law = motion_law(lay, 84)
    cf = d4["boundary"]
    for t in recs:
        i = t.tooth
        assert t.height == gear["built"][i] and t.kept_clearance == audit.per_tooth_min[i]
        assert t.kept_clearance > 0.0
        if t.kind == "transmission":
            assert t.set_by == "full" and t.partner_flex_tooth == -1 and np.isnan(t.generator_angle)
            continue
        b = lay.bounds[lay.sector[i]] if lay.index[i] <= 10 else lay.bounds[lay.sector[i] + 1]
        assert t.generator_angle == pytest.approx(b, abs=1e-12)
        assert t.set_by == ("formula" if t.height < 0.7 - 1e-9 else "formula: full")
        assert t.r_ari == pytest.approx(cf.r_cr + t.w + cf.h_s, abs=1e-12)
        assert t.formula == pytest.approx(cf.r_fix - t.r_ari, abs=1e-12)
        if t.set_by == "formula":
            assert t.height == pytest.approx(t.formula, abs=1e-12)
        assert t.phi == pytest.approx(lay.delta[i], abs=1e-12)  # w is taken at the tooth's angle from the boundary
        # the partner: the flexspline tooth whose centre line stands nearest the rigid tooth at that angle, every
        # tooth placed by its material angle from the axis (docs/models.md 3.1)
        mat = ((2 * pi * np.arange(84) / 84 + law(t.generator_angle) - t.generator_angle + pi) % (2 * pi)) - pi
        rot, shift = tooth_pose(drive.law, mat, drive.r_m, frame_angle=np.full(84, t.generator_angle))
        on_line = shift + drive.r_m * np.stack([np.cos(rot), np.sin(rot)], axis=-1)
        ang = np.arctan2(on_line[:, 1], on_line[:, 0])
        near = int(np.argmin(np.abs((ang - lay.centres[i] + pi) % (2 * pi) - pi)))
        assert t.partner_flex_tooth == near
        assert t.partner_angle == pytest.approx(mat[near], abs=1e-12)
