"""The clearance engine's kernels against independent computations (docs/models.md 5).

- :func:`wgcad.clearance.distance.signed_clearance` on random polygon pairs at random poses against shapely
  (distance apart; the deepest vertex of either polygon inside the other, measured to its outline, when
  overlapping; the overlap's area), including a pair where only the second polygon's vertex lies inside;
- :func:`wgcad.clearance.distance.outline_distance`'s nearest edge and position against the distance they name;
- :func:`wgcad.clearance.refine.apart_pairs` (the distance of teeth apart, both teeth posed) against dense
  polygons of the exact curves, and its points against the distance they are apart;
- :func:`wgcad.clearance.refine.refine_pairs`'s side and point: the point lies on the curve the side names and
  its exact signed distance to the other tooth is the figure.
"""

import functools

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES
from test_exact import dense_pair

from wgcad.clearance import distance as D
from wgcad.clearance.exact import point_signed_distance
from wgcad.clearance.scene import Scene, clearance_at_poses
from wgcad.constants import REFINE_TOL
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.placement import transform
from wgcad.plane import rotate

#: the dense polygons' own error: 2 x their chord tolerance (one per tooth), as tests/test_refine.py
DENSE_TOL = 1e-7


def _star(n, r0, r1, phase=0.0):
    """A star-shaped (not convex) counter-clockwise polygon of ``2 n`` vertices."""
    a = phase + np.pi * np.arange(2 * n) / n
    r = np.where(np.arange(2 * n) % 2 == 0, r1, r0)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def _reference(pa, pb):
    """Signed clearance and overlap area of two placed outlines, by shapely alone."""
    return dense_pair(pa, pb), shapely.area(shapely.intersection(shapely.Polygon(pa), shapely.Polygon(pb)))


@pytest.mark.parametrize("seed", range(4))
def test_signed_clearance_of_random_pairs_is_shapely_s(seed):
    rng = np.random.default_rng(seed)
    a = D.Template(_star(5, 0.6, 1.5, 0.1))
    b = D.Template(_star(3, 0.3, 1.0, 0.4) * [1.6, 0.7])
    K = 150 if seed else 40  # below and above the pair count split between two threads
    rot_a, rot_b = rng.uniform(-np.pi, np.pi, K), rng.uniform(-np.pi, np.pi, K)
    shift_a = rng.uniform(-1.0, 1.0, (K, 2))
    shift_b = shift_a + rng.uniform(-3.0, 3.0, (K, 2))
    got, area = D.signed_clearance(a, rot_a, shift_a, b, rot_b, shift_b, area=True)
    pa, pb = transform(a.local, rot_a, shift_a), transform(b.local, rot_b, shift_b)
    ref = np.array([_reference(pa[k], pb[k]) for k in range(K)])
    np.testing.assert_allclose(got, ref[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(area, ref[:, 1], rtol=0, atol=1e-12)
    assert (got < 0).sum() > 5 and (got > 0).sum() > 5  # both kinds drawn
    # the copies may be handed in already built: the same figures
    again = D.signed_clearance(
        a, rot_a, shift_a, b, rot_b, shift_b, b_geoms=shapely.polygons(pb), a_geoms=shapely.polygons(pa)
    )
    np.testing.assert_array_equal(again, got)


def test_a_vertex_of_the_second_polygon_inside_the_first_sets_the_depth():
    # a wide block with a thin wedge pushed 0.4 into its lower side: no corner of the block lies in the wedge, the
    # wedge's tip lies 0.4 inside the block; both posed away from the origin and turned
    block = D.Template(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 3.0], [0.0, 3.0]]))
    wedge = D.Template(np.array([[4.8, -2.0], [5.2, -2.0], [5.0, 0.4]]))
    rot, shift = np.array([0.7]), np.array([[3.0, -1.5]])
    for first, second in ((block, wedge), (wedge, block)):
        got = D.signed_clearance(first, rot, shift, second, rot, shift)
        assert got[0] == pytest.approx(-0.4, abs=1e-12)
        depth = D.overlap_depth(first, rot, shift, second, rot, shift)
        assert depth[0] == pytest.approx(0.4, abs=1e-12)


def test_the_nearest_edge_and_its_position_name_the_distance():
    rng = np.random.default_rng(11)
    outline = _star(7, 0.5, 1.2, 0.3)
    pts = rng.uniform(-1.6, 1.6, (7000, 2))  # more than one chunk of 40 000 point-edge pairs
    d, edge, along = D.outline_distance(outline, pts)
    np.testing.assert_allclose(d, shapely.distance(shapely.LinearRing(outline), shapely.points(pts)), atol=1e-12)
    assert np.all((along >= 0) & (along <= 1)) and np.all((edge >= 0) & (edge < len(outline)))
    foot = outline[edge] + along[:, None] * (np.roll(outline, -1, axis=0)[edge] - outline[edge])
    np.testing.assert_allclose(np.hypot(*(pts - foot).T), d, rtol=0, atol=1e-12)
    # depth_of: how far each row's deepest point lies inside, 0 for a row wholly outside
    t = D.Template(outline)
    assert not t.local.flags.writeable  # shared by every copy's query: read-only
    rows = np.stack([pts[:10], pts[10:20], np.full((10, 2), 5.0)])
    inside = shapely.contains_xy(t.polygon, rows[..., 0], rows[..., 1])
    want = np.where(inside, D.outline_distance(outline, rows.reshape(-1, 2))[0].reshape(3, 10), 0.0).max(axis=1)
    np.testing.assert_allclose(t.depth_of(rows), want, rtol=0, atol=1e-15)
    assert want[2] == 0.0 and want[:2].max() > 0.0


@functools.cache
def _scene(name):
    return Scene(build_drive(load_design(TEMPLATES / f"{name}.toml")))


@functools.cache
def _dense(name):
    # the same exact curves sampled finely: a conjugate rigid gear's flank is not enveloped again (Drive.sampled_at)
    d = _scene(name).drive.sampled_at(DENSE_TOL / 2)
    return d.flex.tooth_polygon(), d.rigid.tooth_polygon()


def _apart(scene, n=240, reach=0.3):
    """Flexspline tooth poses and the rigid teeth they face, apart by 2 chord gaps to ``reach`` mm."""
    phi = np.linspace(-np.pi / scene.n_w, np.pi / scene.n_w, n)
    z = None if not scene.drive.coned else 0.0
    rot, shift = scene.pose(phi, z)
    det = clearance_at_poses(scene, rot, shift)
    rows, js = [], []
    for v, rigid in ((det.lower, det.lo), (det.upper, det.up)):
        sel = np.nonzero(np.isfinite(v) & (v > 2 * scene.chord_gap) & (v < reach))[0]
        sel = sel[np.linspace(0, len(sel) - 1, min(10, len(sel))).astype(int)]
        rows.append(sel)
        js.append(rigid[sel])
    rows = np.concatenate(rows)
    return rot[rows], shift[rows], np.concatenate(js)


@pytest.mark.parametrize("name", ["d1_involute", "d4_discrete"])
def test_the_distance_of_teeth_apart_is_the_dense_polygons_distance(name):
    scene = _scene(name)
    rot, shift, j = _apart(scene)
    assert len(j) >= 10 and np.ptp(scene.rigid_rot[j]) > 0  # rigid teeth of several poses
    dist, solved, pa, pb = scene.apart_to(rot, shift, j)
    # the batch solves every pair of these involute drives (tests/test_apart.py: 99-100 % over a mesh period); a
    # pair it leaves goes to the general refinement, so only this count shows a batch that gives up too early
    assert solved.all()
    fa, fb = _dense(name)
    a, b = transform(fa, rot, shift), transform(fb, scene.rigid_rot[j], scene.rigid_shift[j])
    ref = np.array([dense_pair(a[k], b[k]) for k in range(len(j))])
    assert np.abs(dist - ref)[solved].max() <= REFINE_TOL + DENSE_TOL
    # the points (the rigid tooth's frame) are the distance apart, each on its own tooth's curve
    np.testing.assert_allclose(np.hypot(*(pa - pb)[solved].T), dist[solved], rtol=0, atol=1e-12)
    on_b = point_signed_distance(scene.rigid_exact, pb[solved])
    assert np.abs(on_b).max() < 1e-9
    # A's point carried back to A's frame (A sits in B's frame at rot - rot_b, R(-rot_b) (shift - shift_b))
    r_rel = rot[solved] - scene.rigid_rot[j[solved]]
    t_rel = rotate(shift[solved] - scene.rigid_shift[j[solved]], -scene.rigid_rot[j[solved]])
    a_local = rotate(pa[solved] - t_rel, -r_rel)
    assert np.abs(point_signed_distance(scene.flex_exact, a_local)).max() < 1e-9


@pytest.mark.parametrize("name", ["d1_involute", "d4_discrete"])
def test_the_refined_figure_is_the_exact_distance_of_its_point(name):
    # pairs apart, touching and overlapping; the point of side 0 is A's, in B's frame, measured against B; that
    # of side 1 is B's, in A's frame, measured against A
    scene = _scene(name)
    phi = np.linspace(-np.pi / scene.n_w, np.pi / scene.n_w, 97)
    rot, shift = scene.pose(phi, None if not scene.drive.coned else 0.0)
    # the flexspline teeth pushed 40 um outwards too (into the rigid teeth): overlapping pairs
    pushed = shift * (1.0 + 0.04 / np.hypot(*shift.T))[:, None]
    rot, shift = np.concatenate([rot, rot]), np.concatenate([shift, pushed])
    det = clearance_at_poses(scene, rot, shift)
    sel = np.nonzero(np.isfinite(det.lower) & (det.lower < 0.1))[0]
    rot, shift, j = rot[sel], shift[sel], det.lo[sel]
    value, side, point = scene.exact_to(rot, shift, j)
    assert (value < 0).any() and (value > 0).any()
    for s, tooth in ((0, scene.rigid_exact), (1, scene.flex_exact)):
        k = side == s
        if k.any():
            np.testing.assert_allclose(point_signed_distance(tooth, point[k]), value[k], rtol=0, atol=1e-9)
    # told which pairs are apart (the polygons' figure), the same figures
    apart = det.lower[sel] > 2 * scene.chord_gap
    again = scene.exact_to(rot, shift, j, apart=apart)[0]
    np.testing.assert_allclose(again, value, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", ["d1_involute", "d4_discrete", "d2"])
def test_teeth_within_a_micrometre_of_touching_match_the_dense_polygons(name):
    # pairs apart moved towards each other along their common normal until they are 0.3 um apart or overlap by
    # 0.3 um: the sign of the figure there comes from the exact curves (the polygons' answer is within their chord
    # of zero), and the refinement must still match the dense polygons
    scene = _scene(name)
    rot, shift, j = _apart(scene)
    dist, solved, pa, pb = scene.apart_to(rot, shift, j)
    rot, shift, j, dist, pa, pb = rot[solved], shift[solved], j[solved], dist[solved], pa[solved], pb[solved]
    n = (pb - pa) / dist[:, None]  # from A's point to B's, the rigid tooth's frame
    fa, fb = _dense(name)
    for eps in (3e-4, -3e-4):
        moved = shift + rotate((dist - eps)[:, None] * n, scene.rigid_rot[j])  # to the global frame
        value, side, point = scene.exact_to(rot, moved, j)
        a, b = transform(fa, rot, moved), transform(fb, scene.rigid_rot[j], scene.rigid_shift[j])
        ref = np.array([dense_pair(a[k], b[k]) for k in range(len(j))])
        assert np.abs(value - ref).max() <= REFINE_TOL + DENSE_TOL, (1e3 * (value - ref)).round(5)
        assert np.all(np.sign(value) == np.sign(eps))


@pytest.mark.parametrize("name", ["d1_involute", "d4_discrete", "d2", "d1_double_arc", "d1_conjugate"])
def test_every_pair_of_a_wave_within_50_um_matches_the_dense_polygons(name):
    # every flexspline tooth of half a wave against both rigid neighbours, not a sample of them: on D4 one upper
    # pair 4.6 um apart has its closest approach at a corner of the rigid tooth against the middle of a long
    # flexspline edge, where the flexspline's vertices are more than the seed margin farther; seeded from the
    # flexspline's vertices alone the batch and the general refinement both gave 0.15 um too much. Each path is
    # checked: the default (the batch for pairs apart), every pair through the general refinement, the batch alone
    scene = _scene(name)
    phi = np.linspace(-np.pi / scene.n_w, np.pi / scene.n_w, 97)
    rot, shift = scene.pose(phi, None if not scene.drive.coned else 0.0)
    det = clearance_at_poses(scene, rot, shift)
    fa, fb = _dense(name)
    for v, rigid in ((det.lower, det.lo), (det.upper, det.up)):
        sel = np.nonzero(np.isfinite(v) & (v < 0.05))[0]
        r, s, j = rot[sel], shift[sel], rigid[sel]
        a, b = transform(fa, r, s), transform(fb, scene.rigid_rot[j], scene.rigid_shift[j])
        ref = np.array([dense_pair(a[k], b[k]) for k in range(len(j))])
        assert len(j) >= 15 and (ref < 0.01).any()
        for apart in (None, np.zeros(len(j), dtype=bool)):
            value, side, point = scene.exact_to(r, s, j, apart=apart)
            assert np.abs(value - ref).max() <= REFINE_TOL + DENSE_TOL, (1e3 * (value - ref)).round(5)
        far = ref > 2 * scene.chord_gap
        dist, solved, pa, pb = scene.apart_to(r[far], s[far], j[far])
        # the batch solves every one of them on the drives without splines (measured: 17-31 pairs a flank, all
        # solved); one it gave up on would still get its figure from the general refinement, so only this shows a
        # batch that stops. On a conjugate flank (a spline of hundreds of segments) it leaves many to the general
        # refinement (measured: D1 double-arc none of 17 a flank solved, D1 conjugate 6 of 9)
        if name in ("d1_involute", "d4_discrete", "d2"):
            assert far.sum() >= 10 and solved.all()
        assert np.abs(dist - ref[far])[solved].max(initial=0.0) <= REFINE_TOL + DENSE_TOL
        np.testing.assert_allclose(np.hypot(*(pa - pb)[solved].T), dist[solved], rtol=0, atol=1e-12)
        assert np.abs(point_signed_distance(scene.rigid_exact, pb[solved])).max(initial=0.0) < 1e-9


def test_integer_poses_give_the_float_poses_figures():
    # poses given as integers (a user's plain lists): the same signed clearances and areas as the same poses in floats
    a = D.Template(_star(5, 0.6, 1.5, 0.1))
    b = D.Template(_star(3, 0.3, 1.0, 0.4) * [1.6, 0.7])
    rot_a, rot_b = np.array([0, 1, 2, 3]), np.array([1, 0, 3, 2])
    shift_a = np.array([[0, 0], [1, 0], [0, 1], [2, 2]])
    shift_b = np.array([[2, 0], [1, 1], [0, 3], [2, 0]])
    got, area = D.signed_clearance(a, rot_a, shift_a, b, rot_b, shift_b, area=True)
    want, want_area = D.signed_clearance(a, rot_a * 1.0, shift_a * 1.0, b, rot_b * 1.0, shift_b * 1.0, area=True)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(area, want_area)
    assert (want < 0).any() and (want > 0).any()
    # a template made from integer coordinates: the float template's figures
    ai, af = D.Template(np.rint(a.local * 10).astype(int)), D.Template(np.rint(a.local * 10))
    bi, bf = D.Template(np.rint(b.local * 10).astype(int)), D.Template(np.rint(b.local * 10))
    got_i = D.signed_clearance(ai, rot_a, shift_a * 10, bi, rot_b, shift_b * 10, area=True)
    got_f = D.signed_clearance(af, rot_a, shift_a * 10, bf, rot_b, shift_b * 10, area=True)
    np.testing.assert_array_equal(got_i[0], got_f[0])
    np.testing.assert_array_equal(got_i[1], got_f[1])
    assert ai.local.dtype == float and not ai.local.flags.writeable
    d, e, u = D.outline_distance(np.rint(a.local * 10).astype(int), np.array([[0.3, 0.2]]))
    dw, ew, uw = D.outline_distance(np.rint(a.local * 10), np.array([[0.3, 0.2]]))
    assert d == dw and e == ew and u == uw
