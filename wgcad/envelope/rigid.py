"""A rigid gear whose flanks are conjugate to the flexspline's teeth under the design's law (docs/models.md 13).

The flank is :func:`wgcad.envelope.space.conjugate_flank` (exact points
joined by chords within 5 nm of the envelope). Where the flexspline tooth
never touches, the tooth is completed by stated rules: from the tip circle to
the flank's first point the tip circle is raised to that point (the tooth's
path there is bounded by its own corners, which a radial wall did not clear),
and from its last point to the root circle the wall runs radially; tip and
root are arcs about the gear's centre. The gear keeps
the design's tooth count, module and radii; only its flanks change.
"""

from __future__ import annotations

from dataclasses import replace
from math import pi

import numpy as np

from wgcad.profiles import pieces as pc
from wgcad.profiles.gear import Gear

from .space import conjugate_flank

__all__ = ["conjugate_rigid_gear"]


def _turn(p: np.ndarray, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return p @ np.array([[c, s], [-s, c]])


def conjugate_rigid_gear(drive, z: float | None = None) -> tuple[Gear, object]:
    """The rigid gear conjugate to ``drive``'s flexspline at section ``z`` (default: the generator's centre
    section), and the :class:`~wgcad.envelope.space.ConjugateFlank` it was made from."""
    rg = drive.rigid
    if not rg.spec.internal:
        raise ValueError("conjugate rigid gears are built for internal deformation (an internal rigid gear)")
    cf = conjugate_flank(drive, z)
    zr = rg.spec.z
    half = pi / zr
    # the flank bounds space 0 (centred on +x) from above; in the tooth frame (rigid tooth centred on +x) it is
    # the tooth's lower flank: turn by -pi/z, then mirror for the upper flank that the half period runs along
    low = _turn(np.asarray(cf.points, float), -half)
    up = low * np.array([1.0, -1.0])
    up = up[np.argsort(np.hypot(*up.T))]  # from the tip (inner) outward
    a_up = np.arctan2(up[:, 1], up[:, 0])
    r_f = rg.r_f
    # the tip starts where the flank does: below the flank's first point the tooth's path is bounded by its own
    # corners, not by the envelope, and a radial wall there was crossed (D1: by 0.72 um over 2.3 um of wall), so
    # the tip circle is raised to the first point (D1 involute: from 82.92 to 82.9223 mm)
    r_a = max(rg.r_a, float(np.hypot(*up[0])))
    # above its last point the wall runs radially to the root circle
    tip_pt = r_a * np.array([np.cos(a_up[0]), np.sin(a_up[0])])
    root_pt = r_f * np.array([np.cos(a_up[-1]), np.sin(a_up[-1])])
    hp = [pc.arc((0.0, 0.0), r_a, 0.0, float(a_up[0]))]
    if np.hypot(*(up[0] - tip_pt)) > 1e-12:
        hp.append(pc.line(tip_pt, up[0]))
    hp += [pc.line(a, b) for a, b in zip(up[:-1], up[1:])]
    if np.hypot(*(root_pt - up[-1])) > 1e-12:
        hp.append(pc.line(up[-1], root_pt))
    if a_up[-1] >= half:
        raise ValueError("the conjugate flank reaches past the middle of the space: the rigid teeth would be pointed")
    hp.append(pc.arc((0.0, 0.0), r_f, float(a_up[-1]), half))
    pieces = tuple(pc.merge_arcs(pc.mirror_path(hp) + hp))
    # the polylines of the outline: the flank's points as they are, the arcs within the drive's tolerance
    tol = drive.tol
    n_tip = max(2, int(np.ceil(r_a * a_up[0] / max(tol, 1e-4))) + 1)
    n_root = max(2, int(np.ceil(r_f * (half - a_up[-1]) / max(tol, 1e-4))) + 1)
    tip = r_a * np.stack([np.cos(np.linspace(0, a_up[0], n_tip)), np.sin(np.linspace(0, a_up[0], n_tip))], -1)
    ang = np.linspace(a_up[-1], half, n_root)
    root = r_f * np.stack([np.cos(ang), np.sin(ang)], -1)
    half_period = np.concatenate(
        [tip, up if np.hypot(*(up[0] - tip_pt)) <= 1e-12 else np.vstack([tip_pt, up])[1:], root]
    )
    keep = np.concatenate([[True], np.hypot(*np.diff(half_period, axis=0).T) > 1e-9])
    half_period = half_period[keep]
    mirror = half_period[::-1] * np.array([1.0, -1.0])
    period = np.concatenate([mirror, half_period[1:]])
    gamma = 2.0 * pi / zr
    k = np.arange(zr)[:, None]
    ang = np.arctan2(period[:-1, 1], period[:-1, 0])[None, :] + k * gamma + rg.spec.phase
    rad = np.hypot(period[:-1, 0], period[:-1, 1])[None, :]
    outline = np.stack([rad * np.cos(ang), rad * np.sin(ang)], -1).reshape(-1, 2)
    for arr in (half_period, period, outline):
        arr.setflags(write=False)
    gear = Gear(
        replace(rg.spec, form="conjugate", tip_radius=r_a),
        rg.r,
        r_a,
        r_f,
        None,
        float(2.0 * r_a * a_up[0]),
        half_period,
        period,
        outline,
        tol,
        pieces,
    )
    return gear, cf
