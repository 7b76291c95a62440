"""Derived figures of the templates against hand calculation (theory.md 2.1, 3.3, 3.4, 9)."""

from math import cos, pi, sin, tan

import numpy as np
import pytest

from conftest import TEMPLATES
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.report import drive_report, format_summary, mesh_figures


def drive(name):
    return build_drive(load_design(TEMPLATES / f"{name}.toml"))


def test_theory_check_d1_depth_2m_clearances_quarter_m():
    # theory.md 2.1: x_g 3.1, x_b 3.2, h_a* 1, c* 0.25, W0 = 1.1 m -> depth 2 m, both clearances 0.25 m
    m = 0.8
    mf = mesh_figures(drive("d1_involute"))
    assert mf["depth_of_engagement_mm"] == pytest.approx(2 * m, abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)


def test_d1_minor_axis_tip_gap_by_hand():
    # four-force law, section II at phi = pi/2 (theory.md 3.4), written out here
    m, beta, W0 = 0.8, np.deg2rad(35.0), 1.1 * 0.8
    D = 8 / cos(beta) - pi * (pi - 2 * beta + 2 * tan(beta))
    w_minor = W0 * (8 / cos(beta) - 2 * pi * (1 + beta * tan(beta))) / D
    r_ag = 80 + m * (1 + 3.1)
    r_ab = 80.8 + m * (3.2 - 1)
    mf = mesh_figures(drive("d1_involute"))
    assert mf["w_minor_mm"] == pytest.approx(w_minor, abs=1e-6)
    assert mf["tip_gap_minor_um"] == pytest.approx(1e3 * (r_ab - (r_ag + w_minor)), abs=1e-3)


def test_d4_disc_law_by_hand():
    # disc law (theory.md 3.3) at phi = pi/2, section II; D4 template: m 0.4, x = 1, h_a* 0.75, W0 = 1.1 m
    m, beta, W0, ha, c = 0.4, np.deg2rad(30.0), 1.1 * 0.4, 0.75, 0.25
    A = pi / 2 - sin(beta) * cos(beta) - beta
    B = -2 * sin(beta) + 4 * beta / pi * sin(beta) + 4 / pi * cos(beta)
    K = W0 / (A - B)
    w_minor = K * ((1 + sin(beta) ** 2) - 2 * sin(beta) - B)
    r_ag, r_ab = 17.2 + m * (ha + 1.0), 17.6 + m * (1.0 - ha)
    r_fg, r_fb = 17.2 - m * (ha + c - 1.0), 17.6 + m * (1.0 + ha + c)
    mf = mesh_figures(drive("d4_discrete"))
    assert mf["depth_of_engagement_mm"] == pytest.approx(r_ag + W0 - r_ab, abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(1e3 * (r_fb - r_ag - W0), abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(1e3 * (r_ab - r_fg - W0), abs=1e-6)
    # um figures are reported to 1 nm
    assert mf["tip_gap_minor_um"] == pytest.approx(1e3 * (r_ab - r_ag - w_minor), abs=1e-3)


def test_d3_external_deformation_by_hand():
    # internal-toothed flexspline squeezed inward by W0 = m onto an external rigid gear, x = 0:
    # depth 2 m, clearances 0.25 m (the mirror image of theory.md 2.1's check)
    m = 0.9
    mf = mesh_figures(drive("d3_external"))
    assert mf["w_major_mm"] == pytest.approx(-m)
    assert mf["depth_of_engagement_mm"] == pytest.approx(2 * m, abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)
    assert mf["tip_gap_minor_um"] > 0  # out of mesh on the minor axis


def test_coning_raises_deformation_at_the_open_end():
    d = drive("d1_involute")
    rep = drive_report(d)
    ends = rep["mesh_at_face_ends"]
    # W0(z) = W0 (l - z)/(l - z_h): l = 160, z_h = 18 -> W0(0) = W0 * 160/142
    assert ends["z_0_mm"]["w_major_mm"] == pytest.approx(0.88 * 160 / 142, abs=1e-6)
    assert ends["z_30_mm"]["w_major_mm"] == pytest.approx(0.88 * 130 / 142, abs=1e-6)


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"])
def test_every_template_builds_and_summarises(name):
    rep = drive_report(drive(name))
    text = format_summary(rep)
    assert "depth of engagement" in text
    for g in ("flexspline", "rigid"):
        assert rep[g]["tip_thickness_mm"] >= 0.2 * rep["drive"]["module_mm"]
    if rep["flexspline"]["form"] == "cycloidal":
        # rack vs exact: p * 2 rho / r at the root (see test_profiles), reported in um
        assert rep["flexspline"]["cycloid_rack_vs_exact_um"] == pytest.approx(1e3 * pi * 0.8 * 0.4 / 80, rel=1e-3)
