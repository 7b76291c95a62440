"""Tests of wgcad.export.formats.gear_data: span W_k and pin dimensions (closed forms) against measurements taken on the gear outline."""

import math

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.export.formats.gear_data import data_lines, gear_data
from wgcad.profiles.involute import inv

INVOLUTE = ["d1_involute", "d2", "d3_external", "d4_discrete"]
TOL = 1e-4  # mm: outlines sampled at 0.1 um for these comparisons

# The outline's vertices lie on the exact curve; a caliper or pin touching
# between two vertices sees the chord, at most the chord tolerance away.
# 2 x TOL covers that for both flanks.
MEAS_TOL = 2 * TOL


@pytest.fixture(scope="module", params=INVOLUTE)
def drive(request):
    return build_drive(load_design(TEMPLATES / f"{request.param}.toml"), tol=TOL)


def test_span_closed_form_matches_a_caliper_on_the_outline(drive):
    for g in (drive.flex, drive.rigid):
        span = gear_data(g, TOL)["span"]
        if g.spec.internal:
            assert span is None  # no span measurement of internal teeth
            continue
        k, z = span["k"], g.spec.z
        pitch = 2 * math.pi / z
        # caliper jaws perpendicular to the bisector of teeth 0..k-1, touching their outer flanks
        beta = g.spec.phase + (k - 1) * pitch / 2
        u = np.array([-math.sin(beta), math.cos(beta)])
        P = g.outline
        ang = (np.arctan2(P[:, 1], P[:, 0]) - g.spec.phase + pitch / 2) % (2 * math.pi) - pitch / 2
        R = np.hypot(P[:, 0], P[:, 1])
        on_flanks = (ang > -pitch / 2) & (ang < (k - 0.5) * pitch) & (R > g.r_f + 0.3 * (g.r_a - g.r_f))
        proj = P[on_flanks] @ u
        assert proj.max() - proj.min() == pytest.approx(span["W_mm"], abs=MEAS_TOL)
        # the textbook form: m cos a ((k - 0.5) pi + z inv a) + 2 x m sin a - thinning cos a
        sp = g.spec
        book = (
            sp.module * math.cos(sp.alpha) * ((k - 0.5) * math.pi + z * inv(sp.alpha))
            + 2 * sp.shift * sp.module * math.sin(sp.alpha)
            - sp.thinning * math.cos(sp.alpha)
        )
        assert span["W_mm"] == pytest.approx(book, abs=1e-9)


def test_pin_dimension_pins_touch_both_flanks(drive):
    for g in (drive.flex, drive.rigid):
        pins = gear_data(g, TOL)["pins"]
        assert pins is not None
        rho = 0.5 * pins["pin_diameter_mm"]
        R_c = pins["pin_centre_radius_mm"]
        ring = shapely.LinearRing(g.outline)
        pitch = 2 * math.pi / g.spec.z
        # a space centre: half a pitch from a tooth centre (tooth centres at phase + k pitch)
        a = g.spec.phase + pitch / 2
        centre = shapely.Point(R_c * math.cos(a), R_c * math.sin(a))
        assert ring.distance(centre) == pytest.approx(rho, abs=MEAS_TOL)
        # and the pin sits in the space, not in the tooth: moving it 1 um deeper makes it overlap
        deeper = R_c + (1e-3 if g.spec.internal else -1e-3)
        c2 = shapely.Point(deeper * math.cos(a), deeper * math.sin(a))
        assert ring.distance(c2) < rho - 1e-4
        c = 1.0 if g.spec.z % 2 == 0 else math.cos(math.pi / (2 * g.spec.z))
        expect = 2 * R_c * c + (-1 if g.spec.internal else 1) * pins["pin_diameter_mm"]
        assert pins["M_mm"] == pytest.approx(expect, rel=1e-15)


def test_data_lines_name_every_figure(drive):
    lines = data_lines("flexspline", gear_data(drive.flex, 1e-3))
    text = "\n".join(lines)
    for word in (
        "module m",
        "teeth z",
        "profile shift",
        "pressure angle",
        "tip diameter",
        "root diameter",
        "pitch diameter",
        "outline tolerance = 1 um",
    ):
        assert word in text


ALL = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"]


@pytest.mark.parametrize("name", ALL)
def test_parts_and_generate_state_one_inspection(name):
    # issue 23: the part set's gear data and generate's report gave two specifications of one gear (D1
    # flexspline: W27 = 66.5225 against W28 = 68.8842; no pins at all for cycloidal teeth in the part set)
    from wgcad.profiles.measure import workshop_figures

    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    for g in (d.flex, d.rigid):
        gd, wf = gear_data(g, d.tol), workshop_figures(g)
        if wf["span"] is None or wf["span"].get("k") is None:
            assert gd["span"] is None
        else:
            assert (gd["span"]["k"], gd["span"]["W_mm"]) == (wf["span"]["k"], wf["span"]["w_k_mm"])
            assert gd["span"]["rule"] == wf["span"]["k_rule"]
        p = wf["pins"]
        if not (p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]):
            assert gd["pins"] is None  # neither states a pin that checks nothing
            assert not [x for x in data_lines("g", gd) if x.startswith("dimension")]
            continue
        key = "between_pins_mm" if g.spec.internal else "over_pins_mm"
        assert (gd["pins"]["pin_diameter_mm"], gd["pins"]["M_mm"]) == (p["pin_diameter_mm"], p[key])
        # the printed pin is the pin the dimension uses (1 um steps: three decimals say it exactly)
        line = [x for x in data_lines("g", gd) if x.startswith("dimension")][0]
        assert (
            f"pin {p['pin_diameter_mm']:.3f} mm" in line
            and float(f"{p['pin_diameter_mm']:.3f}") == p["pin_diameter_mm"]
        )


@pytest.mark.parametrize("name", INVOLUTE)
def test_sensitivities_to_tooth_thickness_match_the_closed_forms(name):
    # span: W_k = ... - thinning cos(a) (the textbook form above), so dW/ds = cos(a) exactly; pins: a thicker tooth
    # moves the pin centre along the flank normal: dM/ds = cos(a) / sin(a_M) over pins, minus that between pins (the
    # centre's pressure angle a_M from R_M = r_b / cos(a_M)); the code takes central differences of 1 um
    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    for g in (d.flex, d.rigid):
        gd = gear_data(g, d.tol)
        if gd["span"] is not None:
            assert gd["span"]["dW_per_thickness"] == pytest.approx(math.cos(g.spec.alpha), rel=1e-6)
        p = gd["pins"]
        a_m = math.acos(g.r_base / p["pin_centre_radius_mm"])
        c = 1.0 if g.spec.z % 2 == 0 else math.cos(math.pi / (2 * g.spec.z))
        sign = -1.0 if g.spec.internal else 1.0  # a thicker internal tooth narrows the space: the pins sit further in
        assert p["dM_per_thickness"] == pytest.approx(sign * c * math.cos(g.spec.alpha) / math.sin(a_m), rel=1e-4)


def test_a_conjugate_rigid_gear_states_its_envelope_residual():
    """A conjugate rigid gear's gear data and the drive report give the envelope's residual: its exact points' distance
    from the envelope condition (Newton's, below 1e-9 mm, docs/models.md 13.2) and its chords' (within the chord
    tolerance); an involute gear states none."""
    from wgcad.report.drive import gear_figures

    drive = build_drive(load_design(TEMPLATES / "d1_conjugate.toml"))
    g = drive.rigid
    assert g.spec.form == "conjugate"
    assert 0 <= g.envelope_residual_mm < 1e-9
    assert 0 < g.envelope_sagitta_mm <= drive.tol
    data = gear_data(g, drive.tol)
    assert data["envelope_residual_mm"] == g.envelope_residual_mm
    assert any(line.startswith("envelope residual = ") for line in data_lines("rigid", data))
    fig = gear_figures(g, drive.rigid_rim_radius)
    assert fig["envelope_residual_mm"] == pytest.approx(g.envelope_residual_mm, rel=1e-2)
    # a finer sampling keeps the same envelope (the flank is not enveloped again)
    assert g.sampled_at(1e-4).envelope_residual_mm == g.envelope_residual_mm
    plain = build_drive(load_design(TEMPLATES / "d1_involute.toml")).rigid
    assert plain.envelope_residual_mm is None and "envelope_residual_mm" not in gear_data(plain, 1e-3)
    assert "envelope_residual_mm" not in gear_figures(plain, 90.0)
