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
