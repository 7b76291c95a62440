"""Derived figures of the templates against hand calculation (docs/models.md 2.1, 3.3, 3.4, 9)."""

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
    # docs/models.md 2.1: x_g 3.1, x_b 3.2, h_a* 1, c* 0.25, W0 = 1.1 m -> depth 2 m, both clearances 0.25 m
    # (the teaching template's textbook teeth)
    m = 0.8
    mf = mesh_figures(drive("d1_involute_nominal"))
    assert mf["depth_of_engagement_mm"] == pytest.approx(2 * m, abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(250 * m, abs=1e-6)


def test_rebuilt_d1_tips_on_one_circle_depth_w0():
    # templates/d1_involute.toml: h_a* = (1 + x_b - x_g) / 2 = 0.55 puts both tips on 82.92 mm, so the depth of
    # engagement is W0 (0.97625 m at the centre line); the radial clearances on the major axis are each tip's
    # distance to the other gear's root there
    m, W0 = 0.8, 0.97625 * 0.8
    r_ag = 80 + m * (3.1 + 0.55)
    r_ab = 80.8 + m * (3.2 - 0.55)
    r_fg = 80 + m * (3.1 - 0.55 - 0.25)
    r_fb = 80.8 + m * (3.2 + 0.55 + 0.25)
    assert r_ag == pytest.approx(r_ab, abs=1e-12)
    mf = mesh_figures(drive("d1_involute"))
    assert mf["depth_of_engagement_mm"] == pytest.approx(r_ag + W0 - r_ab, abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(1e3 * (r_fb - (r_ag + W0)), abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(1e3 * (r_ab - (r_fg + W0)), abs=1e-6)


def test_d1_minor_axis_tip_gap_by_hand():
    # four-force law, section II at phi = pi/2 (docs/models.md 3.4), written out here
    m, beta, W0 = 0.8, np.deg2rad(35.0), 0.97625 * 0.8
    D = 8 / cos(beta) - pi * (pi - 2 * beta + 2 * tan(beta))
    w_minor = W0 * (8 / cos(beta) - 2 * pi * (1 + beta * tan(beta))) / D
    r_ag = 80 + m * (0.55 + 3.1)
    r_ab = 80.8 + m * (3.2 - 0.55)
    mf = mesh_figures(drive("d1_involute"))
    assert mf["w_minor_mm"] == pytest.approx(w_minor, abs=1e-6)
    assert mf["tip_gap_minor_um"] == pytest.approx(1e3 * (r_ab - (r_ag + w_minor)), abs=1e-3)


def test_d4_disc_law_by_hand():
    # disc law (docs/models.md 3.3) at phi = pi/2, section II; D4 template: m 0.4, x = 1, h_a* 0.75, W0 = 1.1 m
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
    # internal-toothed flexspline squeezed inward by W0 = m onto an external rigid gear, x = 0, h_a* = 0.5 (both
    # tips on one circle): the depth of engagement is W0 = m, each clearance the tip's distance to the other
    # gear's root on the major axis (the mirror image of docs/models.md 2.1's check)
    m, ha, c = 0.9, 0.5, 0.25
    r_g, r_b = 135.0, 134.1  # internal flexspline 300 teeth, external rigid 298
    r_ag, r_fg = r_g - ha * m, r_g + (ha + c) * m  # internal teeth: tips inward
    r_ab, r_fb = r_b + ha * m, r_b - (ha + c) * m
    W0 = m
    mf = mesh_figures(drive("d3_external"))
    assert mf["w_major_mm"] == pytest.approx(-m)
    assert mf["depth_of_engagement_mm"] == pytest.approx(r_ab - (r_ag - W0), abs=1e-9)
    assert mf["clearance_flex_tip_major_um"] == pytest.approx(1e3 * ((r_ag - W0) - r_fb), abs=1e-6)
    assert mf["clearance_rigid_tip_major_um"] == pytest.approx(1e3 * ((r_fg - W0) - r_ab), abs=1e-6)
    assert mf["tip_gap_minor_um"] > 0  # out of mesh on the minor axis


def test_coning_raises_deformation_at_the_open_end():
    d = drive("d1_involute")
    rep = drive_report(d)
    ends = rep["mesh_at_face_ends"]
    # W0(z) = W0 (l - z)/(l - z_h): l = 160, z_h = 18 -> W0(0) = W0 * 160/142: the 1.1 m [S1] states at the open end
    W0 = 0.97625 * 0.8
    assert ends["z_0_mm"]["w_major_mm"] == pytest.approx(W0 * 160 / 142, abs=1e-6)
    assert ends["z_0_mm"]["w_major_mm"] == pytest.approx(1.1 * 0.8, abs=1e-6)
    assert ends["z_30_mm"]["w_major_mm"] == pytest.approx(W0 * 130 / 142, abs=1e-6)


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


# ----------------------------------------------------------------------------- workshop figures (issue 13)
import re  # noqa: E402

from wgcad.design import with_changes  # noqa: E402
from wgcad.errors import DesignError  # noqa: E402


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"])
def test_summary_shows_no_negative_thickness_and_leads_with_workshop_figures(name):
    rep = drive_report(drive(name))
    text = format_summary(rep)
    for line in text.splitlines():
        if line.strip().startswith("change per mm of tooth thickness"):
            continue  # a derivative, not a size: between pins it is negative by nature (tests/test_gear_data.py)
        if "thickness" in line or "space width" in line or "span" in line or "pins" in line:
            assert not re.search(r"\s-\d", line), line
    for label in (
        "mid-depth diameter",
        "chordal thickness",
        "span W_k over k teeth",
        "pin (ball) diameter",
        "dimension over / between pins",
        "smallest concave radius",
    ):
        assert label in text
    for g in ("flexspline", "rigid"):
        w = rep[g]["workshop"]
        assert w["mid_depth"]["arc_mm"] > 0 and w["mid_depth"]["chordal_mm"] > 0
        assert (w["span"] is None) == rep[g]["internal_teeth"]
        pins = w["pins"]
        assert ("between_pins_mm" in pins) == rep[g]["internal_teeth"]
        if not rep[g]["pitch_circle_within_teeth"]:
            # the virtual pitch figures stay in the data, not in the summary
            assert (
                "@pitch" not in text
                or rep["flexspline"]["pitch_circle_within_teeth"]
                or rep["rigid"]["pitch_circle_within_teeth"]
            )


def test_d1_pitch_circles_outside_the_teeth_are_not_shown_as_negative_widths():
    # issue 13: D1 printed a space width of -0.607 mm at the pitch circle, which lies outside the teeth
    rep = drive_report(drive("d1_involute"))
    assert not rep["flexspline"]["pitch_circle_within_teeth"] and not rep["rigid"]["pitch_circle_within_teeth"]
    assert min(rep["flexspline"]["space_width_pitch_mm"], rep["rigid"]["tooth_thickness_pitch_mm"]) < 0  # virtual
    # and the JSON says so next to the values (issue 21: a consumer could not tell)
    assert rep["flexspline"]["pitch_figures"].startswith("virtual") and rep["rigid"]["pitch_figures"].startswith(
        "virtual"
    )
    assert drive_report(drive("d4_discrete"))["flexspline"]["pitch_figures"] in (
        "measured",
        rep["rigid"]["pitch_figures"],
    )
    text = format_summary(rep)
    assert "@pitch" not in text and "pitch circle lies outside the teeth" in text


def test_chosen_diameter_and_pin_come_from_the_design():
    d = drive("d4_discrete").design
    dd = with_changes(d, flexspline={"measure_diameter": 35.3, "pin_diameter": 0.72})
    rep = drive_report(build_drive(dd))
    w = rep["flexspline"]["workshop"]
    assert w["at_chosen_diameter"]["diameter_mm"] == pytest.approx(35.3)
    assert w["pins"]["pin_diameter_mm"] == 0.72 and w["pins"]["pin_diameter_source"] == "design"
    assert "chosen diameter" in format_summary(rep)


@pytest.mark.parametrize(
    "change,field,words",
    [
        ({"measure_diameter": 34.2}, "flexspline.measure_diameter", "off the flanks"),
        ({"pin_diameter": 0.3}, "flexspline.pin_diameter", "does not stand out of the teeth"),
        ({"pin_diameter": 2.5}, "flexspline.pin_diameter", "must be in [0.1 m = 0.04, 5 m = 2] mm"),
    ],
)
def test_measurement_choices_that_cannot_be_measured_are_refused(change, field, words):
    d = drive("d4_discrete").design
    with pytest.raises(DesignError) as e:
        drive_report(build_drive(with_changes(d, flexspline=change)))
    assert e.value.field == field and words in str(e.value), str(e.value)


def test_fixed_never_prints_negative_zero():
    # issue 23: "-0.0000 arcmin" of wind-up at no load
    from wgcad.report.text import fixed

    assert fixed(-1e-9, 4) == "0.0000" and fixed(-0.0, 3, 8) == "   0.000"
    assert fixed(-0.00006, 4) == "-0.0001" and fixed(2.5, 1) == "2.5"


def test_load_table_has_no_negative_zero(capsys):
    from wgcad.cli import main

    for name in ("d3_external", "d1_cycloidal"):  # these printed -0.000 N m and -0.0000 arcmin
        main(["audit", str(TEMPLATES / f"{name}.toml"), "--torque-nm", "0", "--cam-offset-um", "20"])
    out = capsys.readouterr().out
    assert not re.search(r"-0\.0+\b", out), out


def test_negative_radial_clearance_is_flagged():
    # issue 23: a coning section with a tip clearance of -21.4 um went unflagged in generate's summary
    from wgcad.design import load_design
    from wgcad.design.schema import with_changes
    from wgcad.drive import build_drive
    from wgcad.report.drive import drive_report, format_summary

    d = load_design(TEMPLATES / "d1_involute.toml")
    w0 = d.generator.w0_coef
    for coef, flagged in ((w0, False), (w0 * 1.5, True)):  # 1.5 W0 drives the tips into the rigid roots
        rep = drive_report(build_drive(with_changes(d, generator={"w0_coef": coef})))
        text = format_summary(rep)
        negatives = [
            v
            for sec in [rep["mesh"], *rep.get("mesh_at_face_ends", {}).values()]
            for k, v in sec.items()
            if k in ("clearance_flex_tip_major_um", "clearance_rigid_tip_major_um", "tip_gap_minor_um") and v < 0
        ]
        assert bool(negatives) == flagged
        assert ("WARNING" in text and "collide radially" in text) == flagged, text
