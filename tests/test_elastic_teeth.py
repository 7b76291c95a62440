"""Tooth contacts of the elastic model (wgcad.deformation.elastic.teeth): the gaps are the clearance engine's."""

from pathlib import Path

import numpy as np
import pytest

from wgcad.clearance.engine import Scene, clearance_at_poses
from wgcad.deformation.elastic.teeth import flank_contacts
from wgcad.design import load_design
from wgcad.drive import build_drive
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
        for dv in ((0.0, 0.0), (0.01, -0.02), (-0.03, 0.01)):
            rot, shift = tooth_pose(drive.law_at(z), phi, drive.r_m)
            shift = shift + np.array(dv)
            ref = clearance_at_poses(scene, rot, shift, third=False)
            got = flank_contacts(scene, rot, shift)
            for key, j in (("lower", "lo"), ("upper", "up")):
                assert np.array_equal(got[key].rigid, ref[j])
                assert np.abs(got[key].gap - ref[key]).max() < 1e-12
                n_over += int((ref[key] < 0).sum())
                n = got[key].normal
                assert np.allclose(np.hypot(n[:, 0], n[:, 1]), 1.0)
    assert n_over > 0  # the overlapping branch was exercised
