"""Entry gap and clearance of teeth passing through a loaded (or any) rim shape, with the exact 2D engine (docs/models.md 5)."""

from __future__ import annotations



import numpy as np

from wgcad.clearance.engine import Scene, clearance_at_poses
from wgcad.clearance.scene import refine_min
from wgcad.placement import pose_from_displacements, tooth_pose

from .loaded import displacements_many

__all__ = ["passing_poses", "entry_gap", "entry_gaps"]


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


def _tip_excess(scene: Scene, law, phi):
    # the exact tip arc against the rigid tip circle, as the engine's entry crossing (docs/models.md 5)
    rot, shift = passing_poses(scene, law, phi)
    return -scene.tip_radial(rot, shift)


def _poses_many(scene: Scene, laws, phis):
    """:func:`passing_poses` of several laws at once (one ring-field evaluation per load state)."""
    out = []
    for phi, (w, v, th) in zip(phis, displacements_many(laws, phis)):
        mat = phi * (scene.z_b - scene.z_g) / scene.z_b
        out.append(pose_from_displacements(phi, w, v, th, scene.drive.r_m, mat - phi))
    return out


def _crossings(scene: Scene, laws, step_deg: float) -> list[float]:
    """Tooth angle of the entry crossing of each law (NaN when the tips never cross), rad.

    Bracketed on the ``step_deg`` grid, then each bracket cut in 63 three
    times over and the last one, 3.5e-8 rad wide at 0.5 deg, closed by linear
    interpolation: the tip excess is smooth there, so the root is within
    ~1e-15 rad. Every stage evaluates all laws together.
    """
    sgn = scene.entry_sign
    t = np.deg2rad(np.arange(step_deg, 90.0 + 0.5 * step_deg, step_deg))
    poses = _poses_many(scene, laws, [sgn * t] * len(laws))
    out = [float("nan")] * len(laws)
    br = {}
    for k, (rot, shift) in enumerate(poses):
        f = -scene.tip_radial(rot, shift)
        cross = np.nonzero((f[:-1] >= 0.0) & (f[1:] < 0.0))[0]
        if cross.size:
            i = int(cross[-1])
            br[k] = (t[i], t[i + 1], f[i], f[i + 1])
    ks = list(br)
    for _ in range(3):
        xs = [np.linspace(br[k][0], br[k][1], 64)[1:-1] for k in ks]
        poses = _poses_many(scene, [laws[k] for k in ks], [sgn * x for x in xs])
        for k, x, (rot, shift) in zip(ks, xs, poses):
            a, b, fa, fb = br[k]
            X = np.concatenate([[a], x, [b]])
            F = np.concatenate([[fa], -scene.tip_radial(rot, shift), [fb]])
            j = int(np.nonzero((F[:-1] >= 0.0) & (F[1:] < 0.0))[0][-1])
            br[k] = (X[j], X[j + 1], F[j], F[j + 1])
    for k in ks:
        a, b, fa, fb = br[k]
        out[k] = float(sgn * (a + (b - a) * fa / (fa - fb)))
    return out


def entry_gaps(scene: Scene, laws, step_deg: float = 0.5) -> list[tuple[float, float]]:
    """:func:`entry_gap` of several laws; the exact-curve refinement of all of them in one engine call."""
    phis = _crossings(scene, laws, step_deg)
    ok = [i for i, p in enumerate(phis) if np.isfinite(p)]
    out = [(float("nan"), float("nan"))] * len(laws)
    if not ok:
        return out
    poses = _poses_many(scene, [laws[i] for i in ok], [np.array([phis[i]]) for i in ok])
    rot = np.array([r[0] for r, _ in poses])
    shift = np.array([s[0] for _, s in poses])
    # the gap on the exact tooth curves, as the audit reports it (polygons only find the pair)
    det = refine_min(scene, rot, shift, clearance_at_poses(scene, rot, shift))
    for k, i in enumerate(ok):
        out[i] = (float(det["min"][k]), phis[i])
    return out


def entry_gap(scene: Scene, law, step_deg: float = 0.5) -> tuple[float, float]:
    """Entry gap (docs/models.md 5) of teeth entering the mesh through ``law``'s first wave.

    The clearance when a tooth's tip circle crosses the rigid tip circle on
    the entry side (outermost crossing between the major axis and a quarter
    turn), the crossing bracketed on a ``step_deg`` grid and refined by
    Brent's method to 1e-12 rad. Internal deformation.

    Returns
    -------
    (gap mm, phi rad)
        NaN, NaN when the tips never cross.
    """
    return entry_gaps(scene, [law], step_deg)[0]
