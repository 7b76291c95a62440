"""Tests of wgcad.export.formats.stl: extruded rings are closed solids of the right volume, STL bytes are reproducible."""

import numpy as np
import pytest
import shapely
import trimesh

from wgcad.errors import GeometryError, OutputError
from wgcad.export.formats.stl import STL_HEADER, ring_solid, stl_bytes, write_stl

HEIGHT = 12.5

# manifold3d snaps 2D coordinates to a 1e-8 mm grid (Clipper2); measured
# vertex moves <= 5.2e-9 mm. Bounds of the in-memory mesh are checked to that.
SNAP_TOL = 1e-8

# Volume of the in-memory (float64) solid against shapely area * height. The
# snapping above changes the area of these outlines by ~2e-12 relative
# (measured); 1e-9 would still catch a single lost tooth (~1e-3 relative).
VOLUME_REL_TOL_FLOAT64 = 1e-9

# STL stores float32: each coordinate moves by up to half the float32
# spacing, 2**-18 mm = 3.8 um at 64..128 mm, i.e. <= 6e-8 relative. The
# volume, a sum over ~5e4 triangles of rounding errors of both signs, moves
# far less: measured 1.3e-8 (external) and 2.4e-8 (internal ring) relative,
# 8e-4 and 2.5e-3 mm^3. 1e-6 is above the worst case of a coherent 3 x 6e-8
# scaling and still catches a lost tooth (~1e-3).
VOLUME_REL_TOL_FLOAT32 = 1e-6
COORD_TOL_FLOAT32 = 2.0**-18 + SNAP_TOL


def toothed(z, r_root, r_tip, per_tooth=60, phase=0.0):
    """(z * per_tooth, 2) CCW outline of z trapezoidal teeth between r_root and r_tip."""
    t = np.linspace(0.0, 2 * np.pi, z * per_tooth, endpoint=False) + phase
    u = (t * z / (2 * np.pi)) % 1.0  # position within one pitch, 0..1
    # flat root, straight-ish flanks, flat tip: a trapezoid in (u, r)
    s = np.clip(4.0 - 10.0 * np.abs(u - 0.5), 0.0, 1.0)
    r = r_root + (r_tip - r_root) * s
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def circle(r, n=720):
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def expected_volume(outer, holes):
    polygon = shapely.Polygon(outer, holes)
    assert polygon.is_valid
    return polygon.area * HEIGHT


def check_solid(mesh, outer, holes, rel_tol, coord_tol):
    assert mesh.is_watertight
    assert mesh.is_volume
    assert mesh.euler_number == 2 - 2 * len(holes)  # genus = number of holes
    volume = expected_volume(outer, holes)
    drift = mesh.volume / volume - 1.0
    assert abs(drift) <= rel_tol
    lo, hi = outer.min(axis=0), outer.max(axis=0)
    np.testing.assert_allclose(mesh.bounds[0], [lo[0], lo[1], 0.0], rtol=0, atol=coord_tol)
    np.testing.assert_allclose(mesh.bounds[1], [hi[0], hi[1], HEIGHT], rtol=0, atol=coord_tol)
    return drift


# external teeth (flexspline-like, 200 teeth, 12k points) with a circular bore
EXTERNAL = (toothed(200, 79.0, 80.6), [circle(70.0)])
# internal teeth (circular-spline-like): circular outside, toothed hole
INTERNAL = (circle(95.0), [toothed(202, 80.9, 79.3, phase=0.01)])


@pytest.fixture(scope="module", params=["external", "internal"])
def case(request):
    outer, holes = EXTERNAL if request.param == "external" else INTERNAL
    return outer, holes, ring_solid(outer, holes, HEIGHT)


@pytest.fixture(scope="module")
def external_solid():
    return ring_solid(*EXTERNAL, HEIGHT)


def test_solid_is_closed_and_has_polygon_volume(case):
    outer, holes, mesh = case
    check_solid(mesh, outer, holes, VOLUME_REL_TOL_FLOAT64, SNAP_TOL)
    assert mesh.vertices.dtype == np.float64


def test_reloaded_stl_keeps_volume(case, tmp_path):
    outer, holes, mesh = case
    path = tmp_path / "ring.stl"
    write_stl(path, mesh)
    assert path.stat().st_size == 84 + 50 * len(mesh.faces)
    back = trimesh.load(path, force="mesh")  # merges float32 vertices again
    assert len(back.faces) == len(mesh.faces)
    drift = check_solid(back, outer, holes, VOLUME_REL_TOL_FLOAT32, COORD_TOL_FLOAT32)
    print(f"STL float32 relative volume drift: {drift:.2e}")


def test_stl_bytes_are_deterministic(tmp_path, external_solid):
    outer, holes = EXTERNAL
    write_stl(tmp_path / "a.stl", external_solid)
    write_stl(tmp_path / "b.stl", ring_solid(outer, holes, HEIGHT))  # built anew
    a = (tmp_path / "a.stl").read_bytes()
    assert a == (tmp_path / "b.stl").read_bytes()
    assert a[:80] == STL_HEADER.ljust(80, b"\0")
    assert not a.startswith(b"solid")  # else readers may take it for ASCII STL


def test_clockwise_input_is_reoriented():
    outer, holes = EXTERNAL
    # outer clockwise, hole counter-clockwise: both the "wrong" way round
    # (manifold3d's positive fill rule would silently make this empty)
    mesh = ring_solid(outer[::-1], [holes[0]], HEIGHT)
    check_solid(mesh, outer, holes, VOLUME_REL_TOL_FLOAT64, SNAP_TOL)
    outer, holes = INTERNAL
    mesh = ring_solid(outer[::-1], [holes[0][::-1]], HEIGHT)
    check_solid(mesh, outer, holes, VOLUME_REL_TOL_FLOAT64, SNAP_TOL)


def test_repeated_points_are_removed(external_solid):
    outer, holes = EXTERNAL
    reference = external_solid
    dirty_outer = np.vstack([np.repeat(outer, 2, axis=0), outer[:1]])  # doubled + closing vertex
    dirty_hole = np.vstack([holes[0], holes[0][:1], holes[0][:1]])
    mesh = ring_solid(dirty_outer, [dirty_hole], HEIGHT)
    check_solid(mesh, outer, holes, VOLUME_REL_TOL_FLOAT64, SNAP_TOL)
    assert len(mesh.vertices) == len(reference.vertices)
    assert stl_bytes(mesh) == stl_bytes(reference)


def test_bad_input_raises():
    outer, holes = EXTERNAL
    with pytest.raises(ValueError, match="height"):
        ring_solid(outer, holes, 0.0)
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        ring_solid(np.zeros((10, 3)), [], HEIGHT)
    with pytest.raises(GeometryError, match="at least 3"):
        ring_solid([[0, 0], [1, 0], [1, 0], [0, 0]], [], HEIGHT)
    # a hole crossing the outer boundary is not a ring
    with pytest.raises(GeometryError, match="not a valid polygon"):
        ring_solid(outer, [circle(80.0)], HEIGHT)
    # a self-intersecting (figure-eight) outline
    with pytest.raises(GeometryError, match="not a valid polygon"):
        ring_solid([[0, 0], [1, 1], [1, 0], [0, 1]], [], HEIGHT)


def test_unwritable_path(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    mesh = ring_solid(circle(10.0, 64), [circle(5.0, 64)], 1.0)
    with pytest.raises(OutputError, match="not writable"):
        write_stl(blocker / "ring.stl", mesh)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
