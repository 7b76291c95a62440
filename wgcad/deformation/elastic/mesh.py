"""Entry gap and clearance of teeth passing through a loaded (or any) rim shape, with the exact 2D engine (docs/models.md 5)."""

from __future__ import annotations



import numpy as np
from scipy.optimize import brentq

from wgcad.clearance.engine import Scene, clearance_at_poses
from wgcad.clearance.scene import refine_min
from wgcad.placement import tooth_pose

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


def _crossing(scene: Scene, law, step_deg: float) -> float:
    """Tooth angle of the entry crossing of ``law`` (NaN when the tips never cross), rad."""
    sgn = scene.entry_sign
    t = np.deg2rad(np.arange(step_deg, 90.0 + 0.5 * step_deg, step_deg))
    f = _tip_excess(scene, law, sgn * t)
    cross = np.nonzero((f[:-1] >= 0.0) & (f[1:] < 0.0))[0]
    if cross.size == 0:
        return float("nan")
    i = int(cross[-1])
    t0 = brentq(lambda x: float(_tip_excess(scene, law, np.array([sgn * x]))[0]), t[i], t[i + 1], xtol=1e-12)
    return float(sgn * t0)


def entry_gaps(scene: Scene, laws, step_deg: float = 0.5) -> list[tuple[float, float]]:
    """:func:`entry_gap` of several laws; the exact-curve refinement of all of them in one engine call."""
    phis = [_crossing(scene, law, step_deg) for law in laws]
    ok = [i for i, p in enumerate(phis) if np.isfinite(p)]
    out = [(float("nan"), float("nan"))] * len(laws)
    if not ok:
        return out
    rot = np.empty(len(ok))
    shift = np.empty((len(ok), 2))
    for k, i in enumerate(ok):
        r, s = passing_poses(scene, laws[i], np.array([phis[i]]))
        rot[k], shift[k] = r[0], s[0]
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
