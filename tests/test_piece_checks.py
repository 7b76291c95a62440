"""The exact tooth pieces (wgcad.profiles.pieces) of every kind checked against independent computations: their
derivatives against finite differences of their points, their length against a dense polyline, and their
transforms (reversed, mirrored, rotated) and path helpers against the same transforms applied to the points."""

from __future__ import annotations

import numpy as np
import pytest

from wgcad.profiles import pieces as pc


def _kinds():
    rng = np.random.default_rng(11)
    pts = np.cumsum(rng.uniform(0.2, 1.0, size=(5, 2)), axis=0)
    tan = np.diff(pts, axis=0, prepend=pts[:1] - [0.3, 0.1])
    tan /= np.hypot(*tan.T)[:, None]
    return {
        "arc": pc.arc((0.3, -0.2), 2.5, 0.4, 1.7),
        "arc_cw": pc.arc((1.0, 2.0), 1.5, 2.0, 0.5),
        "line": pc.line((0.5, 1.0), (2.0, -1.5)),
        "cubic": pc.cubic((0.0, 0.0), (1.0, 2.0), (3.0, 1.0), (0.5, -1.0)),
        "spline": pc.spline(pts, tan),
        "involute": pc.involute(0.05, 40.0, 0.1, 0.45),
        "epicycloid": pc.cycloid("epicycloid", 30.0, 1.2, 0.05, 0.6),
        "hypocycloid": pc.cycloid("hypocycloid", 30.0, 1.2, 0.05, 0.6, rot=0.3, flip=-1.0),
        "epicycloid_turned": pc.cycloid("epicycloid", 25.0, 0.9, 0.02, 0.5, rot=-0.7),
    }


KINDS = _kinds()


def _along(p, s):
    return p.point(p.t0 + np.asarray(s) * (p.t1 - p.t0))


S = np.linspace(0.0, 1.0, 41)


@pytest.mark.parametrize("name", KINDS)
def test_derivatives_are_those_of_the_points(name):
    p = KINDS[name]
    lo, hi = min(p.t0, p.t1), max(p.t0, p.t1)
    t = lo + (hi - lo) * np.linspace(0.03, 0.97, 23)
    if p.kind.endswith("cycloid"):  # away from the cusp at u = 0, where d2P/du2 grows like 1/sqrt(u)
        t = lo + (hi - lo) * np.linspace(0.4, 0.97, 23)
    if p.kind == "spline":  # away from the knots, where the second derivative jumps
        t = t[np.abs(t - np.round(t)) > 3e-2]
    # five-point differences: truncation ~h^4 |f^(5)|, rounding ~1e-16 |f| / h, both far below 1e-8 of the scale
    h = 1e-3 * (hi - lo) if p.kind != "spline" else 1e-3

    def fd(f):
        return (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h)

    fd1, fd2 = fd(p.point), fd(p.deriv)
    np.testing.assert_allclose(p.deriv(t), fd1, atol=1e-8 * np.abs(p.deriv(t)).max())
    np.testing.assert_allclose(p.deriv2(t), fd2, atol=1e-8 * max(np.abs(p.deriv(t)).max(), np.abs(fd2).max()))
    assert p.point(t).shape == p.deriv(t).shape == p.deriv2(t).shape == (len(t), 2)


@pytest.mark.parametrize("name", KINDS)
def test_length_is_the_dense_polyline_length(name):
    p = KINDS[name]
    dense = _along(p, np.linspace(0.0, 1.0, 200_001))
    want = float(np.hypot(*np.diff(dense, axis=0).T).sum())
    assert p.length() == pytest.approx(want, rel=1e-8)
    assert p.reversed().length() == pytest.approx(want, rel=1e-8)
    assert p.length(n=128) == pytest.approx(want, rel=1e-8)


@pytest.mark.parametrize("name", KINDS)
def test_transforms_move_the_points(name):
    p = KINDS[name]
    pts = _along(p, S)
    r = p.reversed()
    np.testing.assert_allclose(_along(r, S), pts[::-1], atol=1e-12)
    np.testing.assert_allclose(r.start, p.end, atol=1e-12)
    np.testing.assert_allclose(r.end, p.start, atol=1e-12)
    m = p.mirrored()
    np.testing.assert_allclose(_along(m, S), pts * [1.0, -1.0], atol=1e-12)  # y -> -y, same direction of travel
    for a in (0.0, 0.8, -2.5):
        q = p.rotated(a)
        c, s = np.cos(a), np.sin(a)
        want = np.stack([c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]], axis=-1)
        np.testing.assert_allclose(_along(q, S), want, atol=1e-12)
        np.testing.assert_allclose(q.length(), p.length(), rtol=1e-12)
    if p.kind == "arc":
        assert m.radius == p.radius and np.allclose(m.center, p.center * [1.0, -1.0])


def test_mirror_path_runs_the_image_backwards_and_path_points_concatenates():
    path = [KINDS["line"], pc.line(KINDS["line"].end, (3.0, 0.0)), pc.arc((3.0, 1.0), 1.0, -np.pi / 2, 0.0)]
    img = pc.mirror_path(path)
    assert len(img) == 3
    np.testing.assert_allclose(img[0].start, path[-1].end * [1.0, -1.0], atol=1e-12)
    np.testing.assert_allclose(img[-1].end, path[0].start * [1.0, -1.0], atol=1e-12)
    for a, b in zip(img[:-1], img[1:]):
        np.testing.assert_allclose(a.end, b.start, atol=1e-12)
    pts = pc.path_points(path, n=7)
    assert pts.shape == (21, 2)
    np.testing.assert_allclose(pts[7:14], path[1].point(np.linspace(path[1].t0, path[1].t1, 7)), atol=0)
    assert pc.path_points(path).shape == (48, 2)


def test_merge_arcs_joins_only_arcs_that_continue_each_other():
    a = pc.arc((0.0, 0.0), 2.0, 0.0, 0.5)
    b = pc.arc((0.0, 0.0), 2.0, 0.5, 1.2)
    (m,) = pc.merge_arcs([a, b])
    assert (m.kind, m.t0, m.t1, m.params) == ("arc", 0.0, 1.2, a.params)
    c = pc.arc((0.0, 0.0), 2.0, 1.2, 1.5)
    assert len(pc.merge_arcs([a, b, c])) == 1
    # a gap between them, another circle, the other direction, a line between: kept apart
    assert len(pc.merge_arcs([a, pc.arc((0.0, 0.0), 2.0, 0.6, 1.2)])) == 2
    assert len(pc.merge_arcs([a, pc.arc((0.0, 0.1), 2.0, 0.5, 1.2)])) == 2
    assert len(pc.merge_arcs([a, pc.arc((0.0, 0.0), 2.1, 0.5, 1.2)])) == 2
    assert len(pc.merge_arcs([a, pc.arc((0.0, 0.0), 2.0, 0.5, 0.2)])) == 2
    ln = pc.line(a.end, (5.0, 5.0))
    assert len(pc.merge_arcs([a, ln, b])) == 3
    # within the tolerance: one
    assert len(pc.merge_arcs([a, pc.arc((0.0, 0.0), 2.0 + 1e-13, 0.5 + 1e-13, 1.2)])) == 1
    assert pc.merge_arcs([]) == []


def _hermite(p0, m0, p1, m1, v):
    """The cubic Hermite interpolant at ``v`` in [0, 1] by its basis functions (an independent form of the Bezier)."""
    h00, h10 = 2 * v**3 - 3 * v**2 + 1, v**3 - 2 * v**2 + v
    h01, h11 = -2 * v**3 + 3 * v**2, v**3 - v**2
    return h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1


def test_a_cubic_piece_is_the_hermite_segment_it_is_given():
    """``cubic(p0, m0, p1, m1)``: from ``p0`` to ``p1`` on ``t`` in [0, 1], with the end derivatives given, and in
    between the Hermite interpolant's values (its basis functions, not the Bezier form)."""
    from wgcad.profiles.pieces import cubic

    p0, m0, p1, m1 = np.array([1.0, 2.0]), np.array([3.0, -1.0]), np.array([4.5, 0.5]), np.array([0.5, 2.5])
    c = cubic(p0, m0, p1, m1)
    assert c.kind == "cubic" and (c.t0, c.t1) == (0.0, 1.0)
    np.testing.assert_allclose(c.start, p0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(c.end, p1, rtol=0, atol=1e-14)
    np.testing.assert_allclose(c.deriv([0.0, 1.0]), [m0, m1], rtol=0, atol=1e-13)
    v = np.linspace(0, 1, 11)
    want = np.array([_hermite(p0, m0, p1, m1, x) for x in v])
    np.testing.assert_allclose(c.point(v), want, rtol=0, atol=1e-13)


def test_a_spline_piece_passes_its_points_along_its_tangents():
    """``spline(points, tangents)``: ``t`` in [0, n - 1], through every point at its knot, each segment the
    Hermite interpolant whose end derivatives are the unit tangents times the segment's own chord (so the
    derivative's direction is continuous and its length jumps at a knot between chords of different length)."""
    from wgcad.profiles.pieces import spline

    rng = np.random.default_rng(2)
    n = 6
    ang = np.sort(rng.uniform(0.2, 1.4, n))
    rad = rng.uniform(9.0, 11.0, n)
    p = np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
    d = np.column_stack([-np.sin(ang + 0.1), np.cos(ang + 0.1)])
    s = spline(p, d)
    assert s.kind == "spline" and (s.t0, s.t1) == (0.0, float(n - 1))
    np.testing.assert_allclose(s.point(np.arange(n, dtype=float)), p, rtol=0, atol=1e-13)
    L = np.hypot(*np.diff(p, axis=0).T)
    for k in range(n - 1):
        m0, m1 = d[k] * L[k], d[k + 1] * L[k]
        v = np.linspace(0.0, 1.0, 7)[:-1]
        np.testing.assert_allclose(s.point(k + v), [_hermite(p[k], m0, p[k + 1], m1, x) for x in v], atol=1e-12)
        np.testing.assert_allclose(s.deriv([k + 1e-12])[0], m0, rtol=0, atol=1e-9)
        np.testing.assert_allclose(s.deriv([k + 1 - 1e-12])[0], m1, rtol=0, atol=1e-9)
