"""Tooth profiles against closed forms and independent computations (docs/models.md 2, 8)."""

from dataclasses import replace
from math import pi

import numpy as np
import pytest
import shapely
from scipy import integrate, optimize

from wgcad.errors import DesignError
from wgcad.profiles import cycloid as cy
from wgcad.profiles.gear import ToothSpec, largest_fillet_coef, make_gear
from wgcad.profiles.sampling import chord_deviation

ALPHA = np.deg2rad(20.0)

# (z, module, internal, shift, fillet_coef): D1's gears, a small gear whose root
# lies below the base circle, a plain internal gear, an external-deformation pair
INVOLUTE_CASES = [
    (200, 0.8, False, 3.1, 0.25),
    (202, 0.8, True, 3.2, 0.15),
    (30, 2.0, False, 0.2, 0.3),
    (60, 1.0, True, 0.5, 0.2),
    (300, 0.9, True, 0.0, 0.25),
    (298, 0.9, False, 0.0, 0.25),
]


def _inv(a):
    return np.tan(a) - a


def s_of_R(z, m, x, R, internal, alpha=ALPHA):
    """Tooth thickness at radius R, docs/models.md 2.1, written out independently of wgcad."""
    r = m * z / 2
    rb = r * np.cos(alpha)
    aR = np.arccos(rb / R)
    w = m * (pi / 2 + 2 * x * np.tan(alpha))  # s (external) or e (internal) at the pitch circle
    width = 2 * R * (w / (2 * r) + _inv(alpha) - _inv(aR))
    return 2 * pi * R / z - width if internal else width


def gear(z, m, internal, x, fc, tol=1e-3, **kw):
    return make_gear(ToothSpec(z=z, module=m, internal=internal, shift=x, fillet_coef=fc, **kw), tol)


def _flank_vertices(g):
    """Vertices of the upper flank of the half period that lie on the involute (between tip and fillet)."""
    h = g.half_period
    R = np.hypot(h[:, 0], h[:, 1])
    lo, hi = sorted((g.r_a, g.r_f))
    sel = (R > lo + 1e-9) & (R < hi - 1e-9) & (R > g.r_base)
    return h[sel], R[sel]


@pytest.mark.parametrize("case", INVOLUTE_CASES)
def test_involute_thickness_at_vertices_matches_closed_form(case):
    z, m, internal, x, fc = case
    g = gear(z, m, internal, x, fc, tol=1e-5)  # finer than default: more vertices to check
    pts, R = _flank_vertices(g)
    ang = np.arctan2(pts[:, 1], pts[:, 0])
    # vertices below the fillet tangent are fillet points; keep those on the flank:
    on_flank = np.abs(2 * R * ang - s_of_R(z, m, x, R, internal)) < 1e-6
    assert on_flank.sum() >= 5
    # flank vertices lie on the closed-form involute to 1e-9 mm (exact arithmetic, no discretisation)
    err = np.abs(2 * R[on_flank] * ang[on_flank] - s_of_R(z, m, x, R[on_flank], internal))
    assert err.max() < 1e-9
    # and the thickness accessor agrees at arbitrary radii in the flank zone
    Rs = np.linspace(R[on_flank].min(), R[on_flank].max(), 37)
    np.testing.assert_allclose(g.tooth_thickness(Rs), s_of_R(z, m, x, Rs, internal), rtol=0, atol=1e-9)


@pytest.mark.parametrize("case", INVOLUTE_CASES)
def test_base_pitch_between_all_teeth(case):
    # Every involute flank vertex, unrolled back to the base circle, gives the
    # angle where its involute starts; same-hand flanks of neighbouring teeth
    # start one base pitch p_b = pi m cos(alpha) apart (docs/models.md 8), checked
    # on the assembled outline of the whole gear.
    z, m, internal, x, fc = case
    g = gear(z, m, internal, x, fc, tol=1e-5)
    rb = g.r_base
    nh = len(g.half_period)
    n = len(g.outline) // z
    pts, R = _flank_vertices(g)
    ang = np.arctan2(pts[:, 1], pts[:, 0])
    on = np.abs(2 * R * ang - s_of_R(z, m, x, R, internal)) < 1e-6
    idx = np.nonzero(np.isin(g.half_period, pts[on]).all(axis=1))[0]
    assert len(idx) >= 3
    sign = -1.0 if internal else 1.0  # the upper half holds a space flank on internal gears
    starts = []
    for k in range(z):
        P = g.outline[k * n + (nh - 1) + idx]
        RP = np.hypot(P[:, 0], P[:, 1])
        L = np.sqrt(RP**2 - rb**2)
        eps = np.unwrap(np.arctan2(P[:, 1], P[:, 0]) + sign * (L / rb - np.arctan(L / rb)))
        assert np.ptp(eps) < 1e-12  # all vertices of a flank on one involute
        starts.append(eps[0])
    steps = rb * np.diff(np.unwrap(starts))
    np.testing.assert_allclose(steps, pi * m * np.cos(ALPHA), rtol=0, atol=1e-9)


@pytest.mark.parametrize("case", INVOLUTE_CASES)
def test_every_tooth_symmetric_and_outline_valid(case):
    z, m, internal, x, fc = case
    g = gear(z, m, internal, x, fc)
    o = g.outline
    n = len(o) // z
    assert n * z == len(o)
    gam = 2 * pi / z
    for k in (0, 1, z // 2, z - 1):
        a = -k * gam
        c, s = np.cos(a), np.sin(a)
        # each tooth's points, mirrored about its centre line, are its points reversed
        period = np.vstack([o[k * n : (k + 1) * n], o[((k + 1) % z) * n]]) @ np.array([[c, s], [-s, c]])
        np.testing.assert_allclose(period[::-1] * [1, -1], period, atol=1e-9)
    poly = shapely.Polygon(o)
    assert poly.is_valid and shapely.LinearRing(o).is_simple
    assert g.area() > 0  # counter-clockwise
    assert not np.any(np.all(np.diff(o, axis=0) == 0, axis=1))  # no repeated vertices


def _tooth_half(z, m, x, R, internal, rb):
    """Half angular tooth thickness at R (tooth frame), radial flank extension below the base circle."""
    Re = np.maximum(R, rb)
    return s_of_R(z, m, x, Re, internal) / (2 * Re)


def _fillet_numeric(g, internal):
    """Fillet centre angle and flank tangent radius found by minimising the distance to the
    closed-form flank: independent of wgcad's offset-involute construction."""
    sp = g.spec
    rho = sp.fillet_coef * sp.module
    rb = g.r_base
    Rc = g.r_f - rho if internal else g.r_f + rho

    def nearest(a_c):
        C = Rc * np.array([np.cos(a_c), np.sin(a_c)])

        def dist(R):
            h = _tooth_half(sp.z, sp.module, sp.shift, R, internal, rb)
            return np.hypot(R * np.cos(h) - C[0], R * np.sin(h) - C[1])

        lo, hi = sorted((g.r_a, g.r_f))
        res = optimize.minimize_scalar(dist, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
        return res.fun, res.x

    a_lo = _tooth_half(sp.z, sp.module, sp.shift, Rc, internal, rb) + 1e-9
    a_c = optimize.brentq(lambda a: nearest(a)[0] - rho, a_lo, pi / sp.z, xtol=1e-15)
    return a_c, Rc, rho, nearest(a_c)[1]


@pytest.mark.parametrize("case", INVOLUTE_CASES)
def test_area_against_radial_integral(case):
    # Area inside the toothed boundary = disc + z * integral of R * (angular width) dR,
    # with the flank from docs/models.md 2.1 and the fillet centre found numerically.
    # Chord error of the polyline: |dA| <= perimeter * tol.
    z, m, internal, x, fc = case
    tol = 1e-5
    g = gear(z, m, internal, x, fc, tol=tol)
    a_c, Rc, rho, R_t = _fillet_numeric(g, internal)
    gam2 = pi / z

    def mat_half(R):  # material half-angle about the tooth centre
        if min(R_t, g.r_f) <= R <= max(R_t, g.r_f):
            cosd = np.clip((R * R + Rc * Rc - rho * rho) / (2 * R * Rc), -1, 1)
            return a_c - np.arccos(cosd)
        return _tooth_half(z, m, x, R, internal, g.r_base)

    if internal:
        f = lambda R: R * 2 * (gam2 - mat_half(R))  # noqa: E731 - the hole is the space
        knots, disc = [g.r_a, R_t, g.r_f], g.r_a
    else:
        f = lambda R: R * 2 * mat_half(R)  # noqa: E731
        knots, disc = [g.r_f, R_t, g.r_a], g.r_f
    if not internal and g.r_base > g.r_f:
        knots = sorted(knots + [g.r_base])
    val = sum(integrate.quad(f, a, b, limit=400, epsabs=1e-13)[0] for a, b in zip(knots[:-1], knots[1:]))
    area = pi * disc**2 + z * val
    perim = shapely.LinearRing(g.outline).length
    assert abs(g.area() - area) <= perim * tol


@pytest.mark.parametrize("internal", [False, True])
def test_cycloid_vertices_on_closed_form(internal):
    # Exact epi/hypocycloid on the pitch circle (docs/models.md 2.2): flank vertices at the
    # closed-form angle for their radius; thickness on the pitch circle p/2.
    z, m = (200, 0.8) if not internal else (202, 0.8)
    g = make_gear(ToothSpec(z=z, module=m, internal=internal, form="cycloidal", clearance_coef=0.1))
    r, rho = m * z / 2, m / 4
    h = g.half_period
    R = np.hypot(h[:, 0], h[:, 1])
    ang = np.arctan2(h[:, 1], h[:, 0])
    lo, hi = sorted((g.r_a, g.r_f))
    sel = (R > lo + 1e-9) & (R < hi - 1e-9)
    # independent closed form: epicycloid radius^2 = (r+rho)^2 + rho^2 - 2 rho (r+rho) cos(phi)
    for Ri, ai in zip(R[sel], ang[sel]):
        epi = (Ri >= r) != internal  # external: addendum epicycloid; internal: addendum hypocycloid
        c = r + rho if Ri >= r else r - rho
        cphi = (c * c + rho * rho - Ri * Ri) / (2 * rho * c) * (1 if Ri >= r else -1)
        phi = np.arccos(np.clip(cphi, -1, 1))
        th = rho * phi / r
        if Ri >= r:
            p = np.array(
                [(r + rho) * np.cos(th) - rho * np.cos(th + phi), (r + rho) * np.sin(th) - rho * np.sin(th + phi)]
            )
        else:
            p = np.array(
                [(r - rho) * np.cos(th) + rho * np.cos(th - phi), (r - rho) * np.sin(th) + rho * np.sin(th - phi)]
            )
        a = np.arctan2(p[1], p[0])
        toward_centre = (Ri >= r) != internal
        expected = pi / (2 * z) - a if toward_centre else pi / (2 * z) + a
        assert abs(Ri * (ai - expected)) < 1e-9, (Ri, epi)
    assert g.tooth_thickness(r) == pytest.approx(pi * m / 2, abs=1e-12)


def test_cycloid_area_against_green_integral():
    # Green's theorem on the exact parametric curves, integrated by quad (independent of sampling)
    z, m, tol = 200, 0.8, 1e-5
    g = make_gear(ToothSpec(z=z, module=m, internal=False, form="cycloidal", clearance_coef=0.1), tol)
    r, rho = m * z / 2, m / 4
    q = pi / (2 * z)
    ra = r + 2 * rho - 0.1 * m
    phi_a = cy.roll_angle_at_radius(r, rho, ra, True)

    def green(f, a, b, h=1e-7):
        def integ(t):
            p = f(t)
            d = (f(t + h) - f(t - h)) / (2 * h)
            return 0.5 * (p[0] * d[1] - p[1] * d[0])

        return integrate.quad(integ, a, b, limit=200, epsabs=1e-13)[0]

    def rot(p, a):
        return np.array([np.cos(a) * p[0] - np.sin(a) * p[1], np.sin(a) * p[0] + np.cos(a) * p[1]])

    add = lambda t: rot(cy.epicycloid(r, rho, t) * [1, -1], q)  # noqa: E731
    ded = lambda t: rot(cy.hypocycloid(r, rho, t), q)  # noqa: E731
    psi_a = np.arctan2(*add(phi_a)[::-1])
    half = 0.5 * ra**2 * psi_a + green(add, phi_a, 0.0) + green(ded, 0.0, pi)  # tip arc, addendum, dedendum
    area = 2 * z * half
    perim = shapely.LinearRing(g.outline).length
    assert abs(g.area() - area) <= perim * tol


def test_rack_approximation_is_close_and_exact_at_pitch():
    r, rho = 80.0, 0.2
    R = np.linspace(r - 2 * rho, r + 2 * rho, 501)
    exact = cy.exact_half_angle(r, rho, R, False)
    rack = cy.rack_half_angle(r, rho, R, False)
    # same thickness p/2 at the pitch circle, continuous across it (corrected dedendum form)
    assert cy.rack_half_thickness(rho, 0.0, True) == pytest.approx(pi * rho)
    assert cy.rack_half_thickness(rho, 0.0, False) == pytest.approx(pi * rho)
    err = np.abs(2 * R * (exact - rack))
    # The rack keeps the arc pitch p at every height, the real pitch at radius R
    # is p R / r: the thickness error grows to p * 2 rho / r at the root, where
    # the space closes (closed form); on the pitch circle both are exact.
    p = 4 * pi * rho
    assert err.max() == pytest.approx(p * 2 * rho / r, rel=1e-4)
    assert np.all(err <= p * np.abs(R - r) / r * (1 + 1e-6) + 1e-12)
    assert err[250] < 1e-9


@pytest.mark.parametrize("tol", [1e-3, 1e-4])
def test_chord_tolerance_holds(tol):
    g = gear(200, 0.8, False, 3.1, 0.25, tol=tol)
    h = g.half_period
    # dense exact samples of the involute flank between the first flank vertices
    pts, R = _flank_vertices(g)
    ang = np.arctan2(pts[:, 1], pts[:, 0])
    on = np.abs(2 * R * ang - s_of_R(200, 0.8, 3.1, R, False)) < 1e-6
    Rd = np.linspace(R[on].min(), R[on].max(), 4000)
    half = s_of_R(200, 0.8, 3.1, Rd, False) / (2 * Rd)
    dense = np.stack([Rd * np.cos(half), Rd * np.sin(half)], axis=1)
    line = shapely.LineString(h)
    d = shapely.distance(shapely.points(dense), line)
    assert d.max() <= tol * (1 + 1e-6)
    assert d.max() > tol / 20  # and the density really follows the tolerance (not far finer)


def test_point_count_follows_tolerance():
    n1 = len(gear(200, 0.8, False, 3.1, 0.25, tol=1e-3).outline)
    n2 = len(gear(200, 0.8, False, 3.1, 0.25, tol=1e-5).outline)
    # sagitta ~ L^2 kappa / 8: 100x finer tolerance -> ~10x the points
    assert 5 < n2 / n1 < 15


def test_chord_deviation_helper():
    a = np.array([[0.0, 0.0]])
    b = np.array([[2.0, 0.0]])
    assert chord_deviation(np.array([[1.0, 0.5]]), a, b)[0] == pytest.approx(0.5)
    assert chord_deviation(np.array([[3.0, 0.0]]), a, b)[0] == pytest.approx(1.0)


def test_thinning_reduces_thickness_by_the_allowance():
    g0 = gear(200, 0.8, False, 3.1, 0.25)
    g1 = gear(200, 0.8, False, 3.1, 0.25, thinning=0.01)
    assert g0.tooth_thickness(82.0) - g1.tooth_thickness(82.0) == pytest.approx(0.01 * 82.0 / 80.0, abs=1e-12)
    b0 = gear(202, 0.8, True, 3.2, 0.15)
    b1 = gear(202, 0.8, True, 3.2, 0.15, thinning=0.01)
    assert b0.tooth_thickness(83.0) - b1.tooth_thickness(83.0) == pytest.approx(0.01 * 83.0 / 80.8, abs=1e-12)


@pytest.mark.parametrize(
    "kw, field, words",
    [
        (dict(z=200, module=0.8, internal=False, shift=6.0), "g.shift", "pointed teeth"),
        (dict(z=20, module=1.0, internal=False, shift=-0.5), "g.shift", "undercut"),
        (dict(z=200, module=0.8, internal=False, shift=3.1, tip_radius=81.0), "g.tip_radius", "outside the root"),
        (dict(z=202, module=0.8, internal=True, shift=3.2, root_radius=82.0), "g.tip_radius", "inside the root"),
        (dict(z=202, module=0.8, internal=True, shift=3.2, fillet_coef=0.25), "g.fillet_coef", "largest that fits"),
        (dict(z=60, module=1.0, internal=True, shift=-2.0), "g.shift", "base circle"),
    ],
)
def test_derived_geometry_errors(kw, field, words):
    with pytest.raises(DesignError) as e:
        make_gear(ToothSpec(field="g", **kw))
    assert e.value.field == field
    assert words in str(e.value)


def test_largest_fillet_really_is_the_largest():
    sp = ToothSpec(z=202, module=0.8, internal=True, shift=3.2, field="g")
    best = largest_fillet_coef(sp)
    assert 0.1 < best < 0.25
    make_gear(replace(sp, fillet_coef=best * 0.999))
    with pytest.raises(DesignError):
        make_gear(replace(sp, fillet_coef=best * 1.001))
