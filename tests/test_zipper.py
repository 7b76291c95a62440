"""The zipper triangulation of gear rings (wgcad.export.zipper): the triangles tile the ring exactly (checked with
shapely, an independent polygon library), the solids equal manifold3d's on every template, and the rules that make it
safe are needed (a sparse bore under steep teeth gives a triangle the wrong way round; an undercut outline is left to
manifold3d)."""

import numpy as np
import pytest
import shapely
import trimesh
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.export import stl
from wgcad.export.zipper import _polar, _zip, extruded_ring, zipper_triangles

ALL = sorted(p.stem for p in TEMPLATES.glob("*.toml"))

# The triangles' areas sum to the ring's in floating point: 18,000 terms of ~1e-2 mm^2 against ~3e3 mm^2, each
# rounded to ~1e-16 relative; 1e-11 relative is far above that and far below one lost triangle (~1e-6).
AREA_REL = 1e-11

# The union of the triangles against the ring: GEOS's overlay rounds each of ~18,000 triangles' coordinates
# (~1e-13 mm at 80 mm) and sums their areas again; measured 1e-13..1e-12 relative. An overlap or gap of one
# triangle is ~1e-6.
UNION_REL = 1e-9

# manifold3d snaps the outlines to a 1e-8 mm grid (tests/test_stl.py): its volumes differ from the exact ones by
# ~1e-10 relative (measured up to 2.9e-10 on the templates); a lost tooth is ~1e-3.
MANIFOLD_VOLUME_REL = 1e-9
MANIFOLD_SNAP_MM = 1e-8


def teeth(z, r_root, r_tip, n_per_tooth, lean=0.0, seed=0):
    """(N, 2) counter-clockwise outline of z teeth with steep flanks; ``lean`` tilts each tooth (undercut when large)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * np.pi, z * n_per_tooth, endpoint=False)
    u = (t * z / (2 * np.pi)) % 1.0
    s = np.clip(6.0 - 14.0 * np.abs(u - 0.5), 0.0, 1.0) ** 0.7
    r = r_root + (r_tip - r_root) * s * (1 + 0.02 * rng.standard_normal(len(t)))
    t = t + lean * s * (2 * np.pi / z)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def circle(r, n, phase=0.0):
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False) + phase
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def check_tiling(outer, inner, pts, tri):
    ring = shapely.Polygon(outer, [inner[::-1]])
    assert ring.is_valid
    t = pts[tri]
    u, v = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    area = 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
    assert np.all(area > 0)
    assert abs(area.sum() / ring.area - 1) < AREA_REL
    # no overlap and no gap: the union has the area of the sum and of the ring, and covers the ring
    union = shapely.union_all(shapely.polygons(t))
    assert abs(union.area / ring.area - 1) < UNION_REL
    assert ring.symmetric_difference(union).area < UNION_REL * ring.area
    # every vertex of both outlines is a corner of the tiling (the added ones lie on their edges)
    corners = {tuple(p) for p in pts}
    assert all(tuple(p) in corners for p in np.concatenate([outer, inner]))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("inside", ["bore", "rim"])
def test_triangles_tile_the_ring(seed, inside):
    rng = np.random.default_rng(seed)
    z = int(rng.integers(20, 160))
    n_circle = int(rng.integers(64, 600))
    if inside == "bore":  # external teeth over a sparse bore close below the roots
        outer = teeth(z, 40.0, 41.5, int(rng.integers(8, 40)), seed=seed)
        inner = circle(40.0 - rng.uniform(0.3, 3.0), n_circle, rng.uniform(0, 1))
    else:  # internal teeth inside a rim
        outer = circle(42.0 + rng.uniform(0.3, 3.0), n_circle, rng.uniform(0, 1))
        inner = teeth(z, 41.5, 40.0, int(rng.integers(8, 40)), seed=seed)
    got = zipper_triangles(outer, inner)
    assert got is not None
    pts, tri, m = got
    check_tiling(outer, inner, pts, tri)
    mesh = extruded_ring(outer, inner, 3.0)
    back = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert back.is_watertight and back.is_winding_consistent and back.is_volume
    assert back.euler_number == 0
    assert abs(back.volume / (shapely.Polygon(outer, [inner]).area * 3.0) - 1) < AREA_REL


def test_a_sparse_bore_needs_the_split():
    """Steep teeth just above a sparse bore: the plain zipper turns triangles over (the positivity check is what
    catches it), and splitting the bore's edges mends them."""
    outer = teeth(100, 40.0, 41.5, 40)
    inner = circle(39.5, 200)
    (po, ao), (pi, ai) = _polar(outer), _polar(inner)
    _, area2, _ = _zip(po, ao, pi, ai)
    assert (area2 <= 0).sum() > 10
    assert zipper_triangles(outer, inner, rounds=0) is None
    pts, tri, m = zipper_triangles(outer, inner)
    check_tiling(outer, inner, pts, tri)
    assert len(pts) > len(outer) + len(inner)  # vertices were added on the bore's edges


def test_an_undercut_outline_goes_to_manifold():
    outer = teeth(40, 40.0, 42.0, 40, lean=0.3)  # teeth leaning over their roots: the polar angle turns back
    inner = circle(35.0, 256)
    assert not np.all(np.diff(np.unwrap(np.arctan2(outer[:, 1], outer[:, 0]))) > 0)
    assert zipper_triangles(outer, inner) is None
    mesh = stl.ring_solid(outer, [inner], 3.0)  # manifold3d's triangulation
    assert mesh.is_volume
    assert abs(mesh.volume / (shapely.Polygon(outer, [inner]).area * 3.0) - 1) < MANIFOLD_VOLUME_REL


@pytest.mark.parametrize("name", ALL)
def test_template_solids_equal_manifold(name, monkeypatch):
    from wgcad.export.drive_files import _gear_solid
    from wgcad.profiles.band import gear_band_outline

    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    for gear, rim in ((drive.flex, drive.flex_rim_radius), (drive.rigid, drive.rigid_rim_radius)):
        band = gear_band_outline(gear)
        ours = _gear_solid(drive, gear, band, rim)
        with monkeypatch.context() as m:
            m.setattr(stl, "extruded_ring", lambda *a: None)
            ref = _gear_solid(drive, gear, band, rim)
        assert ours.is_volume
        assert abs(ours.volume / ref.volume - 1) < MANIFOLD_VOLUME_REL
        np.testing.assert_allclose(ours.bounds, ref.bounds, rtol=0, atol=MANIFOLD_SNAP_MM)
