"""Workshop measurements (wgcad.profiles.measure) against independent computations on the templates' gears."""

from math import cos, pi, sin, tan

import numpy as np
import pytest
from conftest import TEMPLATES
from scipy.optimize import minimize_scalar

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.profiles import cycloid as cy
from wgcad.profiles.gear import ToothSpec, make_gear, rotate
from wgcad.profiles.measure import (
    concave_radii,
    flank_zone,
    pins_closed_form,
    pins_numerical,
    span_closed_form,
    span_k_rule,
    span_numerical,
    thickness_at,
    workshop_figures,
)

NAMES = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"]
#: chord tolerance of the outlines the numerical checks use, mm: their vertices lie on the exact
#: curves and chords stay within FINE of them, so an extent or a distance read on them is off by a
#: few FINE at most (the pin centre by FINE / sin of the flank angle to the centre line, ~3 FINE)
FINE = 1e-5


def gears(form=None, internal=None):
    out = []
    for n in NAMES:
        d = build_drive(load_design(TEMPLATES / f"{n}.toml"))
        for g in (d.flex, d.rigid):
            if (form is None or g.spec.form == form) and (internal is None or g.spec.internal == internal):
                out.append(pytest.param(g, id=f"{n}-{g.spec.field}"))
    return out


def inv(a):
    return tan(a) - a


# ----------------------------------------------------------------------------- span
def test_span_textbook_example():
    # z 30, m 2, alpha 20, x 0: the classic rule gives k = 30 * 20/180 + 0.5 = 3.83 -> 4 and
    # W_4 = m cos(a) [(k - 1/2) pi + z inv(a)] = 21.5053 mm (written out here, ISO 21771 form)
    g = make_gear(ToothSpec(z=30, module=2.0, internal=False, fillet_coef=0.38))
    a = np.deg2rad(20.0)
    assert span_k_rule(g) == 4
    w_iso = 2.0 * cos(a) * (3.5 * pi + 30 * inv(a))
    assert w_iso == pytest.approx(21.5053, abs=1e-4)
    assert span_closed_form(g, 4)[0] == pytest.approx(w_iso, abs=1e-12)


@pytest.mark.parametrize("x,thin", [(0.5, 0.0), (-0.3, 0.0), (1.0, 0.05)])
def test_span_with_shift_and_thinning_is_the_iso_form(x, thin):
    # ISO 21771 form: W_k = m cos(a) [(k - 1/2) pi + z inv(a)] + 2 x m sin(a), minus the thinning
    # projected on the base tangent (cos a): both flanks move by thinning/2 along the pitch circle
    z, m, a = 41, 1.25, np.deg2rad(20.0)
    g = make_gear(ToothSpec(z=z, module=m, internal=False, shift=x, thinning=thin, fillet_coef=0.3))
    for k in (3, 5, 7):
        iso = m * cos(a) * ((k - 0.5) * pi + z * inv(a)) + 2 * x * m * sin(a) - thin * cos(a)
        assert span_closed_form(g, k)[0] == pytest.approx(iso, abs=1e-12)


@pytest.mark.parametrize("gear", gears(form="involute", internal=False))
def test_span_closed_form_equals_two_parallel_tangent_lines_on_the_outline(gear):
    fine = make_gear(gear.spec, FINE)
    k0 = workshop_figures(gear)["span"]["k"]
    for k in (k0 - 1, k0, k0 + 1):
        w, rc = span_closed_form(gear, k)
        lo, hi = flank_zone(gear)
        if not lo < rc < hi:
            continue
        wn, rcn = span_numerical(fine, k)
        assert wn == pytest.approx(w, abs=2 * FINE)
        # the jaws touch where the closed form says, to the flank-sampling resolution
        assert rcn == pytest.approx(rc, abs=0.02 * gear.spec.module)


@pytest.mark.parametrize("gear", gears(form="cycloidal", internal=False))
def test_cycloidal_span_numerical_against_the_exact_curve(gear):
    # second method: maximise the distance across the group's axis over the exact cycloid's
    # parameter (continuous), instead of reading it off the sampled outline's vertices
    sp, r, rho = gear.spec, gear.r, gear.rho
    k = workshop_figures(gear)["span"]["k"]
    # the flank's angle from the tooth centre at the pitch circle: a quarter pitch, less the thinning's turn of
    # each flank, thinning / (2 r) (docs/models.md 2.1)
    q = pi * rho / r - sp.thinning / (2 * r)
    gamma = 2 * pi / sp.z
    turn = (k - 1) * gamma / 2.0  # the upper flank of tooth k-1, seen from the group's axis

    def y(phi, curve, mirror):
        p = curve(r, rho, np.array([phi]))
        if mirror:
            p = p * np.array([1.0, -1.0])
        p = rotate(p, q + turn)
        return float(p[0, 1])

    lo, hi = flank_zone(gear)
    best = -np.inf
    for curve, mirror, radius in ((cy.epicycloid, True, gear.r_a), (cy.hypocycloid, False, gear.r_f)):
        epi = curve is cy.epicycloid
        top = float(cy.roll_angle_at_radius(r, rho, radius, epi))
        res = minimize_scalar(
            lambda p: -y(p, curve, mirror), bounds=(0.0, top), method="bounded", options={"xatol": 1e-12}
        )
        best = max(best, -res.fun)
    w_exact = 2 * best  # symmetric group
    w_num, _ = span_numerical(make_gear(sp, FINE), k)
    assert w_num == pytest.approx(w_exact, abs=3 * FINE)
    assert workshop_figures(gear)["span"]["w_k_mm"] == pytest.approx(w_exact, abs=3 * gear.tol)


# ----------------------------------------------------------------------------- pins
@pytest.mark.parametrize("gear", gears(form="involute"))
def test_pins_closed_form_equals_the_pin_centre_found_geometrically(gear):
    fine = make_gear(gear.spec, FINE)
    d0 = workshop_figures(gear)["pins"]["pin_diameter_mm"]
    for d in (d0, d0 * 0.97, d0 * 1.03):
        c = pins_closed_form(gear, d)
        n = pins_numerical(fine, d)
        assert n["centre_radius_mm"] == pytest.approx(c["centre_radius_mm"], abs=5 * FINE)
        assert n["dimension_mm"] == pytest.approx(c["dimension_mm"], abs=10 * FINE)


def test_pins_odd_tooth_count_uses_the_half_angle():
    # odd z: the pins are not opposite; the dimension is 2 R_M cos(pi / 2z) + D
    g = make_gear(ToothSpec(z=31, module=1.0, internal=False, fillet_coef=0.3))
    d = 1.728
    c = pins_closed_form(g, d)
    assert c["dimension_mm"] == pytest.approx(2 * c["centre_radius_mm"] * cos(pi / 62) + d, abs=1e-12)
    n = pins_numerical(make_gear(g.spec, FINE), d)
    assert n["dimension_mm"] == pytest.approx(c["dimension_mm"], abs=10 * FINE)


@pytest.mark.parametrize("gear", gears())
def test_default_pin_stands_out_and_clears_the_root(gear):
    p = workshop_figures(gear)["pins"]
    if gear.spec.form == "cycloidal" and not gear.spec.internal and not p["pin_clear_of_the_root"]:
        # D1 cycloidal's flexspline: its spaces do not narrow toward the root, every pin the rule tries sinks onto
        # the root land (centre at r_f + D/2) and checks no flank; the rule gives none and says so (the span checks it)
        assert p["pin_centre_diameter_mm"] / 2 - p["pin_diameter_mm"] / 2 == pytest.approx(gear.r_f, abs=2 * gear.tol)
        return
    assert p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]
    if "contact_diameter_mm" in p:  # involute: the contact is on the flank
        lo, hi = flank_zone(gear)
        assert 2 * lo <= p["contact_diameter_mm"] <= 2 * hi


@pytest.mark.parametrize("gear", gears(form="cycloidal"))
def test_cycloidal_pins_converge_with_the_outline(gear):
    # numerical figure: the sampled outline at 1 um and at 0.01 um give the same pin centre to
    # a few chord tolerances (the chords of the coarse outline are within 1 um of the curve)
    d = workshop_figures(gear)["pins"]["pin_diameter_mm"]
    a = pins_numerical(gear, d)["centre_radius_mm"]
    b = pins_numerical(make_gear(gear.spec, FINE), d)["centre_radius_mm"]
    assert a == pytest.approx(b, abs=5 * gear.tol)


# ----------------------------------------------------------------------------- thickness
@pytest.mark.parametrize("gear", gears())
def test_thickness_at_mid_depth_equals_the_outline_cut_by_the_circle(gear):
    # independent: where the sampled outline crosses the circle of radius R (linear interpolation
    # between the vertices around it), the angular width of the tooth
    fine = make_gear(gear.spec, FINE)
    t = workshop_figures(gear)["mid_depth"]
    R = t["diameter_mm"] / 2
    half = fine.half_period  # tooth centre (angle 0) to the middle of the space
    Rh = np.hypot(half[:, 0], half[:, 1])
    i = np.nonzero(np.diff(np.sign(Rh - R)) != 0)[0][0]
    f = (R - Rh[i]) / (Rh[i + 1] - Rh[i])
    p = half[i] + f * (half[i + 1] - half[i])
    psi = np.arctan2(p[1], p[0])
    assert t["arc_mm"] == pytest.approx(2 * R * psi, abs=3 * FINE)
    assert t["chordal_mm"] == pytest.approx(2 * R * sin(psi), abs=3 * FINE)


def test_thickness_closed_form_by_hand():
    # external involute tooth, docs/models.md 2.1: s(R) = 2R [s/(2r) + inv(a) - inv(a_R)]
    z, m, x, a = 40, 1.0, 0.2, np.deg2rad(20.0)
    g = make_gear(ToothSpec(z=z, module=m, internal=False, shift=x, fillet_coef=0.3))
    r, rb = z * m / 2, z * m / 2 * cos(a)
    R = 20.5
    s = m * (pi / 2 + 2 * x * tan(a))
    aR = np.arccos(rb / R)
    sR = 2 * R * (s / (2 * r) + inv(a) - inv(aR))
    t = thickness_at(g, R)
    assert t["arc_mm"] == pytest.approx(sR, abs=1e-12)
    assert t["chordal_height_mm"] == pytest.approx(g.r_a - R * cos(sR / (2 * R)), abs=1e-12)


# ----------------------------------------------------------------------------- concave radii
def three_point_radii(pts):
    a, b, c = pts[:-2], pts[1:-1], pts[2:]
    ab, bc, ca = (np.hypot(*(q - p).T) for p, q in ((a, b), (b, c), (c, a)))
    cross = (b - a)[:, 0] * (c - b)[:, 1] - (b - a)[:, 1] * (c - b)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return ab * bc * ca / (2 * np.abs(cross)), cross


@pytest.mark.parametrize("gear", gears(form="involute"))
def test_concave_radii_against_the_curvature_of_the_outline(gear):
    # numerical curvature: circumradius of three consecutive vertices of a fine outline on its
    # concave stretches. The outline runs counter-clockwise around what it encloses: the teeth of
    # an external gear (concave = turning clockwise), the hole of an internal one (concave for the
    # material = turning counter-clockwise)
    fine = make_gear(gear.spec, 1e-6)
    pts = np.asarray(fine.period)
    rad, cross = three_point_radii(pts)
    concave = cross > 1e-18 if gear.spec.internal else cross < -1e-18
    closed = concave_radii(gear)
    smallest = min(closed.values())
    found = float(np.nanmin(rad[concave]))
    # the circumradius of three points on a circle is exact; on the involute it is the curvature
    # radius to second order in the vertex spacing; 1 % covers both
    assert found == pytest.approx(smallest, rel=1e-2)


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"])
def test_a_pin_that_fits_checks_the_tooth_thickness(name):
    # issue 23: D1 cycloidal's flexspline pin (0.720 mm) rested on the root circle (centre at r_f + D/2 =
    # 79.96 mm) and read 160.6400 mm whatever the thinning: a dimension that checks nothing. A pin the rule
    # accepts must touch the flanks: 20 um of tooth thickness moves its dimension by more than 1 um
    from dataclasses import replace

    from wgcad.design import load_design
    from wgcad.drive import build_drive
    from wgcad.profiles.gear import make_gear
    from wgcad.profiles.measure import pin_check, pins_closed_form, pins_numerical

    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    for g in (d.flex, d.rigid):
        p = pin_check(g)
        if not (p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]):
            continue
        measure = pins_closed_form if g.spec.form == "involute" else pins_numerical
        thinner = make_gear(replace(g.spec, thinning=g.spec.thinning + 0.02), g.tol)
        moved = abs(
            measure(thinner, p["pin_diameter_mm"])["dimension_mm"] - measure(g, p["pin_diameter_mm"])["dimension_mm"]
        )
        assert moved > 1e-3, (name, g.spec.internal, moved)
