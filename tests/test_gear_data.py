"""Tests of wgcad.export.gear_data: span W_k and pin dimensions (closed forms) against measurements taken on the gear outline."""

import math

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.export.gear_data import data_lines, gear_data, inv, inv_inverse

INVOLUTE = ["d1_involute", "d2", "d3_external", "d4_discrete"]
TOL = 1e-4  # mm: outlines sampled at 0.1 um for these comparisons

# The outline's vertices lie on the exact curve; a caliper or pin touching
# between two vertices sees the chord, at most the chord tolerance away.
# 2 x TOL covers that for both flanks.
MEAS_TOL = 2 * TOL


@pytest.fixture(scope="module", params=INVOLUTE)
def drive(request):
    return build_drive(load_design(TEMPLATES / f"{request.param}.toml"), tol=TOL)


def test_inv_inverse():
    for a in (1e-4, 0.1, 0.35, 0.8, 1.2):
        assert inv_inverse(float(inv(a))) == pytest.approx(a, rel=1e-12)


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
