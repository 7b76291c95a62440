"""Entry gap and clearance of teeth passing through a loaded (or any) rim shape, with the exact 2D engine (docs/models.md 5)."""

from __future__ import annotations

import numpy as np

from wgcad.clearance.engine import Scene
from wgcad.clearance.entry import entry_passages
from wgcad.placement import pose_from_displacements, tooth_pose

from .loaded import displacements_many

__all__ = ["passing_poses", "law_poses", "entry_gap", "entry_gaps"]


def passing_poses(scene: Scene, law, phi):
    """Poses of a tooth at angles ``phi`` from the major axis as it passes the rigid teeth (rigid frame).

    The generator angle that brings a tooth to ``phi`` puts its material
    angle at ``phi (z_b - z_g)/z_b`` (the mesh period, docs/models.md 7), so every
    tooth at ``phi`` sees the rigid teeth alike; ``law`` holds the rim shape in
    the generator frame (quasi-static: the loaded shape travels with the cam).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    mat = phi * (scene.z_b - scene.z_g) / scene.z_b
    return tooth_pose(law, phi, scene.drive.r_m, frame_angle=mat - phi)


def _poses_many(scene: Scene, laws, phis):
    """:func:`passing_poses` of several laws at once (one ring-field evaluation per load state)."""
    out = []
    for law, phi, (w, v, th) in zip(laws, phis, displacements_many(laws, phis)):
        mat = phi * (scene.z_b - scene.z_g) / scene.z_b
        out.append(pose_from_displacements(phi, w, v, th, scene.drive.r_m, mat - phi, law.tooth_offset))
    return out


def law_poses(scene: Scene, laws):
    """The pose function of :mod:`wgcad.clearance.entry` over ``laws`` (passage ``k`` = ``laws[k]``): all laws in one go."""

    def poses(phi, k):
        phi = np.asarray(phi, dtype=float)
        k = np.asarray(k)
        rot = np.empty(len(phi))
        shift = np.empty((len(phi), 2))
        ks = np.unique(k)
        sel = [np.nonzero(k == j)[0] for j in ks]
        for idx, (r, sh) in zip(sel, _poses_many(scene, [laws[j] for j in ks], [phi[i] for i in sel])):
            rot[idx], shift[idx] = r, sh
        return rot, shift

    return poses


def entry_gaps(scene: Scene, laws, exact: bool = True) -> list:
    """The entry (Delta of [S1], the crossing, the pinch; :class:`wgcad.clearance.entry.EntryPassage`) of teeth
    passing through each of ``laws`` (its first wave, quasi-static: the rim keeps that shape), docs/models.md 5."""
    return entry_passages(scene, law_poses(scene, laws), len(laws), exact=exact)


def entry_gap(scene: Scene, law) -> tuple[float, float]:
    """Delta and where it lies, ``(gap mm, phi rad)``, of teeth passing through ``law``'s first wave (NaN, NaN when the
    tips never cross)."""
    p = entry_gaps(scene, [law])[0]
    return p.delta, p.delta_phi
