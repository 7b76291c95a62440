"""Placement of flexspline teeth on the deformed neutral line (docs/models.md 3.1, 7)."""

from math import pi

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.laws import Ellipse, FourForce, Harmonic
from wgcad.placement import deformed_curve, place_flex_teeth, place_points, place_points_first_order, tooth_angles


@pytest.fixture(scope="module")
def d1():
    return build_drive(load_design(TEMPLATES / "d1_involute.toml"))


def _max_diff(local, law, r_m):
    phi = np.linspace(0, 2 * pi, 200, endpoint=False)
    a = place_points(local, law, phi, r_m)
    b = place_points_first_order(local, law, phi, r_m)
    return np.max(np.hypot(*(a - b).transpose(2, 0, 1)))


@pytest.mark.parametrize("law_cls", [Harmonic, FourForce])
def test_exact_vs_first_order_is_second_order(d1, law_cls):
    # halving W0 must quarter the difference: the first-order form drops only O(W0^2/r_m) terms
    kw = {} if law_cls is Harmonic else {"beta": np.deg2rad(35)}
    r_m = d1.r_m
    e1 = _max_diff(d1.flex.period, law_cls(w0=0.88, r_m=r_m, **kw), r_m)
    e2 = _max_diff(d1.flex.period, law_cls(w0=0.44, r_m=r_m, **kw), r_m)
    assert 3.6 < e1 / e2 < 4.4
    # and the constant is modest: tooth size ~ 2-4 m ~ 2-4 W0
    assert e1 < 5 * 0.88**2 / r_m


def test_centreline_form_drops_a_first_order_term(d1):
    # [S3 eq. 15] applied to flank points misses the radial -s*theta: linear in W0
    r_m = d1.r_m
    loc = d1.flex.period
    phi = np.linspace(0, 2 * pi, 200, endpoint=False)

    def err(w0):
        law = Harmonic(w0=w0, r_m=r_m)
        a = place_points(loc, law, phi, r_m)
        b = place_points_first_order(loc, law, phi, r_m, centreline=True)
        return np.max(np.hypot(*(a - b).transpose(2, 0, 1)))

    assert 1.8 < err(0.88) / err(0.44) < 2.2
    # on the centre line itself (s = 0) the two forms agree to second order
    line = np.stack([np.linspace(r_m - 0.7, r_m + 2.5, 9), np.zeros(9)], axis=1)
    law = Harmonic(w0=0.88, r_m=r_m)
    a = place_points(line, law, phi, r_m)
    b = place_points_first_order(line, law, phi, r_m, centreline=True)
    assert np.max(np.abs(a - b)) < 2.5 * (1.5 * 0.88 / r_m) ** 2


def test_tooth_turns_with_the_neutral_line_tangent(d1):
    # a placed radial segment must stay normal to the placed neutral line
    law, r_m = d1.law, d1.r_m
    phi = np.linspace(0.01, 2 * pi - 0.01, 97)
    seg = np.array([[r_m, 0.0], [r_m + 1.0, 0.0]])
    placed = place_points(seg, law, phi, r_m)
    normal = placed[:, 1] - placed[:, 0]
    h = 1e-6
    tan = (deformed_curve(law, r_m, 0.0, phi + h) - deformed_curve(law, r_m, 0.0, phi - h)) / (2 * h)
    cosang = np.einsum("ij,ij->i", normal, tan) / np.hypot(*normal.T) / np.hypot(*tan.T)
    # ring laws use theta = (v - w')/r_m, the linearised tangent angle: error ~ theta^3 < 1e-5 rad
    assert np.max(np.abs(cosang)) < 1e-5


def test_ellipse_neutral_line_keeps_its_length():
    r_m = 80.0
    law = Ellipse(w0=0.9, r_m=r_m)
    phi = np.linspace(0, 2 * pi, 400_001)
    pts = deformed_curve(law, r_m, 0.0, phi)
    length = np.sum(np.hypot(*np.diff(pts, axis=0).T))
    # polyline of 4e5 chords: length error ~ L (h kappa)^2 / 24 ~ 1e-11 relative
    assert length == pytest.approx(2 * pi * r_m, rel=1e-9)
    # teeth are placed by arc length: equal spacing along the deformed line
    k = np.arange(200)
    origins = deformed_curve(law, r_m, 0.0, 2 * pi * k / 200)
    assert np.allclose(np.roll(origins, -1, axis=0)[0], origins[1])


def test_mesh_period_maps_the_scene_onto_itself(d1):
    # docs/models.md 7: after 2 pi / z_b of generator rotation, every tooth moved one position
    zb = d1.design.drive.z_rigid
    a = place_flex_teeth(d1, 0.3)
    b = place_flex_teeth(d1, 0.3 + 2 * pi / zb)
    c, s = np.cos(2 * pi / zb), np.sin(2 * pi / zb)
    a_rot = a @ np.array([[c, s], [-s, c]])
    # match teeth by centroid: the set of placed teeth is the same
    ca, cb = a_rot.mean(axis=1), b.mean(axis=1)
    idx = np.argmin(np.hypot(*(ca[:, None, :] - cb[None, :, :]).transpose(2, 0, 1)), axis=1)
    assert len(set(idx)) == len(idx)
    assert np.max(np.abs(a_rot - b[idx])) < 1e-9


def test_tooth_on_major_axis_seated_in_rigid_space(d1):
    teeth = place_flex_teeth(d1, 0.0, teeth=[0])
    tip = teeth[0][np.argmax(np.hypot(*teeth[0].T))]
    assert np.hypot(*tip) == pytest.approx(d1.flex.r_a + d1.law.w0, abs=1e-9)
    # symmetric about +x, the middle of a rigid space (reference position, docs/models.md 1)
    assert np.allclose(np.sort(teeth[0][:, 1]), np.sort(-teeth[0][:, 1]), atol=1e-9)


def test_external_deformation_teeth_move_inward():
    d3 = build_drive(load_design(TEMPLATES / "d3_external.toml"))
    t0 = place_flex_teeth(d3, 0.0, teeth=[0])[0]
    R = np.hypot(*t0.T)
    assert R.min() == pytest.approx(d3.flex.r_a - d3.law.w0, abs=1e-9)  # internal tooth tip, pushed in
    _, phi = tooth_angles(300, 298, 0.0)
    assert phi[150] == pytest.approx(pi)


def test_flex_rotation_follows_ratio(d1):
    mat, phi = tooth_angles(200, 202, 2 * pi)
    # one generator turn, rigid fixed: flexspline turns -2/200 of a turn (u_hg = -100)
    assert mat[0] == pytest.approx(-2 * pi / 100)
    assert phi[0] == pytest.approx(-2 * pi / 100 - 2 * pi)


@pytest.mark.parametrize("form", ["involute", "cycloidal"])
def test_deformed_outline_is_simple(form):
    # neighbouring teeth turn by different angles; pointed cycloidal roots then cross
    from wgcad.design import with_changes
    from wgcad.placement import join_teeth

    base = load_design(TEMPLATES / "d3_external.toml")
    des = base if form == "involute" else with_changes(base, tooth={"form": "cycloidal", "clearance_coef": 0.1})
    d3 = build_drive(des)
    import shapely

    for phi_h in (0.0, 0.26):
        outline = join_teeth(place_flex_teeth(d3, phi_h, local=d3.flex.period))
        assert shapely.LinearRing(outline).is_simple
        assert abs(shapely.Polygon(outline).area) > 0


@pytest.mark.parametrize("name", sorted(p.stem for p in TEMPLATES.glob("*.toml")) + ["d3_external-cycloidal"])
def test_deformed_outline_has_no_back_steps_or_near_duplicates(name):
    # issue 13: where neighbouring root lands join, the outline stepped back 0.06-1 um;
    # an outline must have no two neighbouring vertices closer than MIN_VERTEX_SPACING
    from wgcad import constants
    from wgcad.design import with_changes
    from wgcad.placement import join_teeth

    des = load_design(TEMPLATES / f"{name.split('-')[0]}.toml")
    if name.endswith("cycloidal"):
        des = with_changes(des, tooth={"form": "cycloidal", "clearance_coef": 0.1})
    drive = build_drive(des)
    for phi_h in (0.0, 0.26, 1.0):
        o = join_teeth(place_flex_teeth(drive, phi_h, local=drive.flex.period))
        seg = np.diff(np.vstack([o, o[:1]]), axis=0)
        L = np.hypot(*seg.T)
        assert L.min() >= constants.MIN_VERTEX_SPACING
        # a back-step turns the outline by ~180 deg; real corners (tips, fillets) turn by < 70 deg
        cos_turn = (seg * np.roll(seg, -1, axis=0)).sum(axis=1) / (L * np.roll(L, -1))
        assert cos_turn.min() > 0.0, f"{name} at {phi_h}: the outline turns back on itself"
