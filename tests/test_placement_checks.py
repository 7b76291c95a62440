"""The crossing of neighbouring teeth's root ends (wgcad.placement.law._crossing, which join_teeth cuts the outline
at) against shapely's segment intersections, on polylines of small integer coordinates: crossings at segment ends,
parallel segments and a shared junction point all occur there, and shapely's predicates are exact on them."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from wgcad.placement import law


def _first_crossing(tail, head):
    """The first (tail segment, head segment) pair in tail-major order whose segments meet in one point (shapely),
    the point not being the junction of a tail segment's end with a head segment's start; parallel segments never
    cross (the outline's rule: they are joined, not cut)."""
    for i in range(len(tail) - 1):
        p0, p1 = tail[i], tail[i + 1]
        for j in range(len(head) - 1):
            q0, q1 = head[j], head[j + 1]
            r, s = p1 - p0, q1 - q0
            if r[0] * s[1] - r[1] * s[0] == 0:
                continue
            a, b = shapely.LineString([p0, p1]), shapely.LineString([q0, q1])
            if not a.intersects(b):
                continue
            pt = np.array(a.intersection(b).coords[0])
            if np.array_equal(pt, p1) and np.array_equal(pt, q0):
                continue
            return i, j, pt
    return None


@pytest.mark.parametrize("seed", range(40))
def test_first_crossing_equals_shapely_on_integer_polylines(seed):
    rng = np.random.default_rng(seed)
    n, m = rng.integers(2, 7, size=2)
    tail = rng.integers(0, 4, size=(n, 2)).astype(float)
    head = rng.integers(0, 4, size=(m, 2)).astype(float)
    if seed % 4 == 0:
        head[0] = tail[-1]  # a junction: the outline continues from the tail into the head
    want = _first_crossing(tail, head)
    got = law._crossing(tail, head)
    if want is None:
        assert got is None
    else:
        assert got is not None and got[:2] == want[:2], (got, want)
        np.testing.assert_allclose(got[2], want[2], atol=1e-12)


def test_crossing_cases_by_hand():
    # two strokes crossing at (1, 1): segment 0 of each, the point
    hit = law._crossing(np.array([[0.0, 0.0], [2.0, 2.0]]), np.array([[0.0, 2.0], [2.0, 0.0]]))
    assert hit[:2] == (0, 0) and np.allclose(hit[2], [1.0, 1.0])
    # the tail's second segment crosses the head's second: indices count segments from each polyline's start
    tail = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 2.0]])
    head = np.array([[5.0, 5.0], [3.0, 0.0], [1.0, 2.0]])
    i, j, p = law._crossing(tail, head)
    assert (i, j) == (1, 1) and np.allclose(p, [2.0, 1.0])
    # the head starts where the tail ends: a junction, not a crossing
    assert law._crossing(np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([[1.0, 1.0], [2.0, 0.0]])) is None
    # a touch at a segment's end is a crossing (the tail's end on the middle of the head)
    i, j, p = law._crossing(np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([[0.0, 2.0], [2.0, 0.0]]))
    assert (i, j) == (0, 0) and np.allclose(p, [1.0, 1.0])
    # the tail's start on the head's end: also one
    i, j, p = law._crossing(np.array([[1.0, 1.0], [2.0, 2.0]]), np.array([[0.0, 2.0], [1.0, 1.0]]))
    assert (i, j) == (0, 0) and np.allclose(p, [1.0, 1.0])
    # parallel (collinear, overlapping) segments: none; apart: none
    assert law._crossing(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([[1.0, 0.0], [3.0, 0.0]])) is None
    assert law._crossing(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 1.0], [1.0, 2.0]])) is None
    # just beyond either segment's end: none
    assert law._crossing(np.array([[0.0, 0.0], [0.999, 0.999]]), np.array([[0.0, 2.0], [2.0, 0.0]])) is None
    assert law._crossing(np.array([[0.0, 0.0], [2.0, 2.0]]), np.array([[0.0, 2.0], [0.999, 1.001]])) is None


@pytest.mark.parametrize("seed", range(6))
def test_pose_from_displacements_places_points_as_its_definition(seed):
    """A tooth point p goes to R(fa) [origin + R(phi + theta) (p_x + offset - r_m, p_y)], origin = (r_m + w) e_r +
    v e_t at phi (docs/models.md 3.1): computed point by point in complex numbers, for any shape of phi."""
    rng = np.random.default_rng(seed)
    shape = [(5,), (3, 4)][seed % 2]
    phi = rng.uniform(-4, 4, shape)
    w, v, theta = (rng.normal(scale=0.5, size=shape) for _ in range(3))
    fa = rng.uniform(-1, 1, shape) if seed % 3 else rng.uniform(-1, 1)
    off = rng.uniform(-0.1, 0.1, shape) if seed % 2 else rng.uniform(-0.1, 0.1)
    r_m = 40.0 + seed
    rot, shift = law.pose_from_displacements(phi, w, v, theta, r_m, fa, off)
    assert rot.shape == shape and shift.shape == (*shape, 2)
    p = rng.normal(size=2) + [r_m, 0.0]
    e = np.exp(1j * phi)
    origin = (r_m + w) * e + 1j * v * e
    want = np.exp(1j * np.broadcast_to(fa, shape)) * (
        origin + np.exp(1j * (phi + theta)) * ((p[0] + off - r_m) + 1j * p[1])
    )
    got = np.exp(1j * rot) * (p[0] + 1j * p[1]) + (shift[..., 0] + 1j * shift[..., 1])
    np.testing.assert_allclose(got, want, atol=1e-12)
    # the defaults: no frame turn, no offset
    r0, s0 = law.pose_from_displacements(phi, w, v, theta, r_m)
    r1, s1 = law.pose_from_displacements(phi, w, v, theta, r_m, 0.0, 0.0)
    np.testing.assert_array_equal(r0, r1)
    np.testing.assert_array_equal(s0, s1)


def test_tooth_angles_of_chosen_teeth_and_frames_of_any_shape():
    """tooth_angles of some teeth are those teeth's entries of all; tooth_frames gives the cross-section at phi
    (origin (r_m + w) e_r + v e_t, normal at phi + theta: the law's own state) for phi of any shape."""
    from conftest import TEMPLATES

    from wgcad.design import load_design
    from wgcad.drive import build_drive

    mat, phi = law.tooth_angles(200, 202, 0.37)
    m2, p2 = law.tooth_angles(200, 202, 0.37, teeth=[3, 7, 150])
    np.testing.assert_array_equal(m2, mat[[3, 7, 150]])
    np.testing.assert_array_equal(p2, phi[[3, 7, 150]])
    drive = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    grid = np.linspace(-1.0, 2.5, 12).reshape(3, 4)
    origin, ang = law.tooth_frames(drive.law, grid, drive.r_m)
    assert origin.shape == (3, 4, 2) and ang.shape == (3, 4)
    st = drive.law.state(grid.ravel())
    e = np.exp(1j * grid.ravel())
    want = (drive.r_m + st.w) * e + 1j * st.v * e
    np.testing.assert_allclose(origin.reshape(-1, 2), np.stack([want.real, want.imag], axis=-1), atol=1e-12)
    np.testing.assert_allclose(ang.ravel(), grid.ravel() + st.theta, atol=1e-15)
    assert np.abs(st.theta).max() > 1e-3  # the rotation is there to be seen


def test_parallel_and_degenerate_segments_raise_no_warning():
    """Parallel segments divide by zero inside the crossing test; that is expected and says nothing to the user."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert law._crossing(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([[1.0, 0.0], [3.0, 0.0]])) is None
        assert law._crossing(np.array([[0.0, 0.0], [0.0, 0.0]]), np.array([[1.0, 1.0], [1.0, 1.0]])) is None


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d4_sectored"])
@pytest.mark.parametrize("phi", [0.0, 0.7])
def test_join_teeth_on_the_templates(name, phi):
    """The joined outline of a template's placed teeth is simple, runs through every tooth in order, keeps each
    tooth's vertices away from its ends exactly, adds no point off the teeth's own polylines (a crossing lies on
    both), and keeps the minimum vertex spacing everywhere (the closing step too)."""
    from conftest import TEMPLATES

    from wgcad import constants
    from wgcad.design import load_design
    from wgcad.drive import build_drive

    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    teeth = law.place_flex_teeth(drive, phi, local=drive.flex.period)
    K, N, _ = teeth.shape
    out = law.join_teeth(teeth)
    assert shapely.LinearRing(out).is_simple
    lines = shapely.MultiLineString(list(teeth))
    assert shapely.distance(shapely.points(out), lines).max() < 1e-9
    step = np.hypot(*(np.roll(out, -1, axis=0) - out).T)
    assert step.min() >= constants.MIN_VERTEX_SPACING
    # the vertices away from the ends (beyond the 6 join_teeth looks at) are kept, in order, tooth after tooth
    tree = shapely.STRtree(shapely.points(out))
    where = []
    for k in range(K):
        inner = teeth[k][6 : N - 6]
        idx, dist = tree.query_nearest(shapely.points(inner), return_distance=True, all_matches=False)
        assert dist.max() < 1e-12, (k, dist.max())
        pos = idx[1]
        assert np.all(np.diff(pos) > 0)
        where.append(pos[0])
    assert np.all(np.diff(where) > 0)
    assert len(out) >= K * (N - 12)
