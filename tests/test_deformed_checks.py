"""The deformed drive at one generator angle (wgcad.placement.deformed), against what the law and the gear ratio
give in closed form: the neutral line reaches r_m + w0 on the generator's major axis and turns with it, the rim
runs at its own height from the neutral line, the drawing frame turns by phi / u_hb when the flexspline is fixed,
the rim's chords keep the tolerance, and the placed teeth are the law's."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES

from wgcad.design import load_design, with_changes
from wgcad.drive import build_drive
from wgcad.kinematics import gear_ratios
from wgcad.placement.deformed import deformed_state, generator_frame, rim_samples, rotate
from wgcad.placement.law import place_flex_teeth


@pytest.fixture(scope="module")
def d1():
    return build_drive(load_design(TEMPLATES / "d1_involute.toml"))


def test_rotate_is_a_complex_product():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(7, 2))
    for a in (0.0, 0.4, -2.2, np.pi):
        z = (p[:, 0] + 1j * p[:, 1]) * np.exp(1j * a)
        np.testing.assert_allclose(rotate(p, a), np.stack([z.real, z.imag], axis=-1), atol=1e-15)
    q = rng.normal(size=(2, 3, 2))  # any leading shape
    np.testing.assert_allclose(rotate(q, 0.7)[1, 2], rotate(q[1, 2][None], 0.7)[0], atol=1e-15)


def test_generator_frame_by_the_fixed_member(d1):
    assert generator_frame(d1, 0.9) == (0.9, 0.0)
    flex_fixed = build_drive(with_changes(d1.design, drive={"fixed": "flexspline"}))
    u_hb = gear_ratios(200, 202)["u_hb"]
    phi_h, frame = generator_frame(flex_fixed, 0.9)
    assert frame == pytest.approx(0.9 / u_hb, rel=1e-15) and phi_h == pytest.approx(0.9 - 0.9 / u_hb, rel=1e-15)
    st = deformed_state(flex_fixed, 0.9, flex_fixed.tol)
    assert (st.phi_h, st.frame) == (phi_h, frame)
    np.testing.assert_allclose(st.rigid_outline, rotate(flex_fixed.rigid.outline, frame), atol=1e-12)
    np.testing.assert_allclose(st.neutral_phi, rim_samples(flex_fixed, flex_fixed.tol) + phi_h + frame, atol=1e-12)


@pytest.mark.parametrize("tol", [1e-3, 1e-5, 1e-7])
def test_rim_samples_keep_the_chord_tolerance(d1, tol):
    ph = rim_samples(d1, tol)
    n = len(ph)
    assert n >= 720 and ph[0] == 0.0
    np.testing.assert_allclose(np.diff(ph), 2 * np.pi / n, rtol=1e-9)
    sag = d1.r_m * (1 - np.cos(np.pi / n))  # a chord's sagitta on the neutral circle
    assert sag <= tol * 1.0001
    if n > 720:  # the fewest samples that keep it: one fewer would not
        assert d1.r_m * (1 - np.cos(np.pi / (n - 1))) > tol * 0.999


@pytest.mark.parametrize("phi", [0.0, 0.3, -1.1])
def test_neutral_line_peaks_on_the_major_axis_and_the_rim_keeps_its_height(d1, phi):
    st = deformed_state(d1, phi, d1.tol)
    r = np.hypot(*st.neutral.T)
    top = np.arctan2(st.neutral[r.argmax(), 1], st.neutral[r.argmax(), 0])
    step = 2 * np.pi / len(r)
    # two waves: the major axis at phi and phi + pi
    assert min(abs(np.angle(np.exp(1j * (top - phi)))), abs(np.angle(np.exp(1j * (top - phi - np.pi))))) <= step
    assert r.max() == pytest.approx(d1.r_m + d1.law.w0, abs=1e-9)
    assert r.min() < d1.r_m  # the minor axis falls inside
    # the rim is the neutral line offset along its normal by the rim's height: every rim point that far from it
    h = abs(d1.flex_rim_radius - d1.r_m)
    line = shapely.LinearRing(st.neutral)
    dist = shapely.distance(shapely.points(st.rim), line)
    np.testing.assert_allclose(dist, h, atol=2 * d1.tol)
    # the placed teeth are the law's at that generator angle, and the joined outline holds them
    np.testing.assert_allclose(st.flex_teeth, place_flex_teeth(d1, phi, local=d1.flex.period), atol=1e-12)
    assert shapely.LinearRing(st.flex_outline).is_simple
    assert st.flex_phi.shape == (200,)
    np.testing.assert_allclose(st.rigid_outline, d1.rigid.outline, atol=0)


def test_a_cam_offset_moves_the_rim_and_neutral_line():
    """Every cam-offset part (the cam's, the flexspline-borne one turning with the flexspline's rotation, the
    housing's) moves the rim and the neutral line; the teeth are posed with the errors."""
    from dataclasses import replace

    from wgcad.kinematics import flex_rotation
    from wgcad.placement.imperfect import Imperfections, cam_offset, flex_poses
    from wgcad.placement.law import transform

    design = load_design(TEMPLATES / "d2_imperfect.toml")
    drive = build_drive(design)
    imp = replace(Imperfections.from_spec(design.imperfections), cam_flex=0.02, cam_flex_phase=0.3)
    st = deformed_state(drive, 0.4, drive.tol, imp=imp)
    plain = deformed_state(drive, 0.4, drive.tol)
    off = cam_offset(imp, 0.4, flex_rotation(0.4, design.drive.z_flex, design.drive.z_rigid))
    assert np.hypot(*off) > 1e-3  # tens of micrometres
    np.testing.assert_allclose(st.neutral - plain.neutral, np.broadcast_to(off, st.neutral.shape), atol=1e-12)
    np.testing.assert_allclose(st.rim - plain.rim, np.broadcast_to(off, st.rim.shape), atol=1e-12)
    np.testing.assert_allclose(st.flex_teeth, transform(drive.flex.period, *flex_poses(drive, imp, 0.4)), atol=1e-12)
    assert np.abs(st.flex_teeth - plain.flex_teeth).max() > 1e-3


def test_the_outline_joins_the_placed_teeth_and_a_section_takes_its_own_law(d1):
    """The outline is the placed teeth joined; a section z of a coned flexspline is placed and drawn by the law at
    z (its neutral line reaches r_m + w0(z)), which differs from the centre section's; with errors too."""
    from wgcad.placement.imperfect import Imperfections, flex_poses
    from wgcad.placement.law import join_teeth, transform

    assert d1.coned
    st = deformed_state(d1, 0.2, d1.tol)
    np.testing.assert_array_equal(st.flex_outline, join_teeth(st.flex_teeth))
    z = 0.9 * d1.design.drive.face_width if hasattr(d1.design.drive, "face_width") else None
    z = z if z is not None else 10.0
    at = deformed_state(d1, 0.2, d1.tol, z=z)
    law_z = d1.law_at(z)
    assert abs(law_z.w0 - d1.law.w0) > 1e-3
    assert np.hypot(*at.neutral.T).max() == pytest.approx(d1.r_m + law_z.w0, abs=1e-9)
    np.testing.assert_allclose(at.flex_teeth, place_flex_teeth(d1, 0.2, local=d1.flex.period, z=z), atol=1e-12)
    assert np.abs(at.flex_teeth - st.flex_teeth).max() > 1e-3
    design = load_design(TEMPLATES / "d2_imperfect.toml")
    drive = build_drive(design)
    imp = Imperfections.from_spec(design.imperfections)
    sec = deformed_state(drive, 0.4, drive.tol, z=z, imp=imp)
    np.testing.assert_allclose(
        sec.flex_teeth, transform(drive.flex.period, *flex_poses(drive, imp, 0.4, z=z)), atol=1e-12
    )
    centre = deformed_state(drive, 0.4, drive.tol, imp=imp)
    assert np.abs(sec.flex_teeth - centre.flex_teeth).max() > 1e-4
