"""wgcad.export.formats.mesh.Mesh against trimesh, an independent implementation: the same closedness, winding, volume,
Euler number and STL on the real solids, and broken meshes (a hole, a flipped face, turned inside out) refused."""

from __future__ import annotations

import io

import numpy as np
import pytest
import trimesh

from wgcad.export.formats.mesh import Mesh, concatenate
from wgcad.export.formats.stl import STL_HEADER, ring_solid


def _ring():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    r = 80 + 1.2 * (np.sin(100 * t) > 0)  # a toothed outline 80 mm from the origin
    return ring_solid(np.c_[r * np.cos(t), r * np.sin(t)], [np.c_[70 * np.cos(t), 70 * np.sin(t)]], 12.5)


@pytest.fixture(scope="module")
def ring():
    return _ring()


def _tm(m: Mesh):
    return trimesh.Trimesh(m.vertices, m.faces, process=False)


def test_figures_equal_trimesh(ring):
    ref = _tm(ring)
    assert ring.is_watertight and ref.is_watertight
    assert ring.is_winding_consistent and ref.is_winding_consistent
    assert ring.is_volume and ref.is_volume
    assert ring.euler_number == ref.euler_number == 0  # a ring: one handle
    # volume: both sum the same tetrahedra (about different points): 1e-12 relative of ~5e4 mm^3
    assert abs(ring.volume - ref.volume) <= 1e-12 * abs(ref.volume)
    np.testing.assert_array_equal(ring.bounds, ref.bounds)
    np.testing.assert_allclose(ring.face_normals, ref.face_normals, rtol=0, atol=1e-12)


def test_broken_meshes_are_refused_like_trimesh(ring):
    holed = Mesh(ring.vertices, ring.faces[1:])  # one face missing: an open shell
    flipped_f = ring.faces.copy()
    flipped_f[0] = flipped_f[0, ::-1]  # one face wound the wrong way
    flipped = Mesh(ring.vertices, flipped_f)
    inside_out = Mesh(ring.vertices, ring.faces[:, ::-1])
    for m in (holed, flipped, inside_out):
        ref = _tm(m)
        assert m.is_watertight == ref.is_watertight
        assert m.is_winding_consistent == ref.is_winding_consistent
        assert m.is_volume == ref.is_volume is False
    assert inside_out.volume < 0
    assert not holed.is_watertight and flipped.is_watertight and not flipped.is_winding_consistent


def test_stl_reads_back_in_trimesh(ring):
    data = ring.stl_bytes(STL_HEADER)
    assert len(data) == 84 + 50 * len(ring.faces)
    back = trimesh.load(io.BytesIO(data), file_type="stl", force="mesh")  # merges the float32 corners
    assert back.is_volume and len(back.faces) == len(ring.faces)
    assert abs(back.volume / ring.volume - 1) < 1e-6  # float32 corners (tests/test_stl.py)


def test_concatenate_keeps_parts_apart(ring):
    moved = Mesh(ring.vertices + [0, 0, 20.0], ring.faces)
    both = concatenate([ring, moved])
    ref = trimesh.util.concatenate([_tm(ring), _tm(moved)])
    np.testing.assert_array_equal(both.faces, ref.faces)
    assert abs(both.volume - 2 * ring.volume) <= 1e-9 * ring.volume
    assert both.is_volume
