"""Backlash (dead travel) at a generator angle: rigid turn of the flexspline between contact either way (docs/models.md 5)."""

from __future__ import annotations

from math import pi

import numpy as np

from ..placement import tooth_pose, transform
from .scene import Scene
from .search import _fold

__all__ = ["backlash"]


def backlash(scene: Scene, phi_h: float, z=None) -> float:
    """Dead travel at generator angle ``phi_h`` (rad): rigid-body rotation of the flexspline between contact on either side, rad.

    NaN when teeth interfere at this angle (there is no dead travel).
    Only teeth in radial overlap with the rigid teeth can touch, and a tooth
    whose clearance ``d`` exceeds ``R_max * delta_best`` cannot touch before
    the best found (a rotation ``delta`` moves no point further than
    ``R_max delta``): those are skipped. One wave is enough when the waves
    are identical.
    """
    k = np.arange(scene.z_g)
    mat = 2 * pi * k / scene.z_g + phi_h / scene.ratios["u_hg"]
    phi = mat - phi_h
    if scene.z_g % scene.n_w == 0 and scene.z_b % scene.n_w == 0:
        keep = np.abs(_fold(phi, 2 * pi)) <= pi / scene.n_w + 1e-12
        phi, mat = phi[keep], mat[keep]
    rot0, shift0 = tooth_pose(scene.law(z), phi, scene.drive.r_m, frame_angle=phi_h)
    live = np.nonzero(scene.radial_bound(transform(scene.flex_tip_local, rot0, shift0)) <= 0.0)[0]
    if live.size == 0:
        return float("inf")
    rot0, shift0 = rot0[live], shift0[live]
    lo, up, _ = scene.neighbours(shift0, rot0)
    r_max = float(np.hypot(*transform(scene.flex_local, rot0, shift0).reshape(-1, 2).T).max())

    def turned(i, d):
        # the tooth turned by d about the gear axis
        c, s = np.cos(d), np.sin(d)
        sh = shift0[i]
        return rot0[i] + d, np.array([[c * sh[0] - s * sh[1], s * sh[0] + c * sh[1]]])

    def contact_angle(i, j, direction):
        # rotation of tooth i (in `direction`) that brings its clearance to rigid tooth j to zero
        jj = np.array([j])

        def f(d):
            r, sh = turned(i, direction * d)
            return float(scene.clearance_to(np.array([r]), sh, jj)[0])

        f0 = f(0.0)
        if f0 == 0.0:
            return 0.0
        # a rotation by d moves no point further than r_max d: f0 / r_max is the
        # nearest the root can be; expand from there to a sign change, then brentq
        step = max(abs(f0) / r_max, 1e-12)
        a, b = 0.0, np.sign(f0) * step
        fb = f(b)
        while np.sign(fb) == np.sign(f0) and abs(b) < scene.gamma_b:
            a, b = b, 2.0 * b
            fb = f(b)
        if np.sign(fb) == np.sign(f0):
            return float("inf")
        from scipy.optimize import brentq  # lazy: scipy.optimize costs 0.4-0.8 s to import (issue 13)

        return brentq(f, min(a, b), max(a, b), xtol=1e-13)

    sides = []
    for idx, direction in ((up, 1.0), (lo, -1.0)):
        d = scene.clearance_to(rot0, shift0, idx)
        if d.min() < 0:
            return float("nan")  # teeth interfere here: there is no dead travel (no need to look further)
        sides.append((idx, direction, d))
    total = 0.0
    for idx, direction, d in sides:
        order = np.argsort(d)
        best = np.inf
        for i in order:
            # a tooth needs at least d / r_max to touch: once that is not below
            # the best found, no later tooth can beat it
            if d[i] / r_max >= best:
                break
            best = min(best, contact_angle(int(i), int(idx[i]), direction))
        total += best
    return float(total)
