"""Tooth contacts of the elastic model (wgcad.elastic.teeth): the gaps are the clearance engine's."""

from pathlib import Path

import numpy as np
import pytest

from wgcad.clearance.engine import Scene, clearance_at_poses
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic.teeth import flank_contacts, pair_contacts
from wgcad.placement import tooth_pose

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal"])
def test_flank_gaps_are_the_engines_signed_clearance(name):
    # flank_contacts computes the engine's definition itself (shortest segments, deepest vertices) to get the
    # points and normals in the same pass: the figures must be the engine's to round-off, apart and overlapping
    drive = build_drive(load_design(ROOT / "templates" / f"{name}.toml"))
    scene = Scene(drive)
    phi = 2 * np.pi * np.arange(drive.design.drive.z_flex) / drive.design.drive.z_flex
    n_over = 0
    for z in (0.0, 30.0):
        for dv in ((0.0, 0.0), (0.01, -0.02), (-0.03, 0.01), (0.06, 0.0)):
            rot, shift = tooth_pose(drive.law_at(z), phi, drive.r_m)
            shift = shift + np.array(dv)
            ref = clearance_at_poses(scene, rot, shift, third=False)
            got = flank_contacts(scene, rot, shift)
            for key, val, rigid in (("lower", ref.lower, ref.lo), ("upper", ref.upper, ref.up)):
                assert np.array_equal(got[key].rigid, rigid)
                assert np.abs(got[key].gap - val).max() < 1e-12
                n_over += int((val < 0).sum())
                n = got[key].normal
                assert np.allclose(np.hypot(n[:, 0], n[:, 1]), 1.0)
    assert n_over > 0  # the overlapping branch was exercised


@pytest.mark.parametrize("name", ["d1_involute_nominal", "d1_cycloidal"])
def test_contact_points_located_on_the_outline_as_geos_does(name):
    # the smooth normals interpolate along the edge nearest to each contact point; _project finds it in numpy:
    # the place along the outline must be shapely.line_locate_point's to 1e-12 mm, for the contact points of
    # both teeth (ends of the shortest segments between placed teeth, deepest vertices) on the real templates
    import shapely

    from wgcad.elastic.teeth import _project
    from wgcad.placement import transform

    drive = build_drive(load_design(ROOT / "templates" / f"{name}.toml"))
    scene = Scene(drive)
    phi = 2 * np.pi * np.arange(drive.design.drive.z_flex) / drive.design.drive.z_flex
    checked = overlapping = 0
    for dv in ((0.0, 0.0), (0.01, -0.02), (-0.03, 0.01)):
        rot, shift = tooth_pose(drive.law_at(0.0), phi, drive.r_m)
        shift = shift + np.array(dv)
        lo, up, _ = scene.neighbours(shift, rot)
        for rigid in (lo, up):
            flex = shapely.polygons(transform(scene.flex_local, rot, shift))
            seg = shapely.get_coordinates(shapely.shortest_line(flex, scene.rigid_geoms[rigid])).reshape(-1, 2, 2)
            g = pair_contacts(scene, rot, shift, rigid)
            for local, r, s, p in (
                (scene.flex_local, rot, shift, g.point),
                (scene.rigid.local, scene.rigid_rot[rigid], scene.rigid_shift[rigid], seg[:, 1]),
            ):
                c, sn = np.cos(r), np.sin(r)
                d = p - s
                q = np.stack([c * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + c * d[:, 1]], axis=-1)
                ab = np.roll(local, -1, axis=0) - local
                L2 = (ab * ab).sum(axis=-1)
                e, t = _project(local, ab, L2, q)
                cum = np.concatenate([[0.0], np.cumsum(np.sqrt(L2))])
                got = cum[e] + t * np.sqrt(L2[e])
                ref = shapely.line_locate_point(shapely.linearrings(local), shapely.points(q))
                per = cum[-1]  # the start vertex is both 0 and the perimeter along the ring
                assert np.abs((got - ref + 0.5 * per) % per - 0.5 * per).max() < 1e-12
                checked += len(q)
            overlapping += int((g.gap < 0).sum())
    assert overlapping > 0  # overlapping pairs (deepest vertices) among them (the 60 um outward shift makes some)
    assert checked > 2000
