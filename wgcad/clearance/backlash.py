"""Backlash (dead travel) at a generator angle: rigid turn of the flexspline between contact either way (docs/models.md 5)."""

from __future__ import annotations

from math import pi

import numpy as np

from ..placement import tooth_pose, transform
from ..plane import rotate
from ..roots import brentq
from .scene import Scene
from .search import _fold

__all__ = ["backlash"]


def backlash(scene: Scene, phi_h: float, z=None, exact: bool = False) -> float:
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
        # the tooth (or teeth, with arrays) turned by d about the gear axis
        if np.ndim(i):
            return rot0[i] + d, rotate(shift0[i], d)
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
        return brentq(f, min(a, b), max(a, b), xtol=1e-13)

    # with ``exact``: polygon figures are within ``gap`` of the curves' (docs/models.md 5)
    gap = scene.chord_gap if exact else 0.0
    sides = []
    for idx, direction in ((up, 1.0), (lo, -1.0)):
        d = scene.clearance_to(rot0, shift0, idx)
        if d.min() + gap < 0:
            return float("nan")  # interfere on the curves too: the polygon figure is within gap of theirs
        if exact:  # whether the teeth touch or interfere is decided on the exact curves
            near = np.nonzero(d < gap)[0]
            if near.size:
                d = d.copy()
                d[near] = scene.exact_to(rot0[near], shift0[near], idx[near])[0]
        if d.min() < 0:
            return float("nan")  # teeth interfere here: there is no dead travel (no need to look further)
        sides.append((idx, direction, d))
    bests, angles = [], []
    for idx, direction, d in sides:
        order = np.argsort(d)
        best = np.inf
        angle = {}
        for i in order:
            # a tooth needs at least d / r_max to touch: once that is not below
            # the best found, no later tooth can beat it (less the polygon-curve gap when exact)
            if (d[i] - gap) / r_max >= best:
                break
            # (a pair the polygons overlap but the curves do not starts from no turn)
            angle[int(i)] = (
                max(contact_angle(int(i), int(idx[i]), direction), 0.0)
                if exact
                else contact_angle(int(i), int(idx[i]), direction)
            )
            best = min(best, angle[int(i)])
        bests.append(best)
        angles.append(angle)
    if exact:
        bests = _exact_sides(scene, turned, sides, angles, bests, gap)
    return float(sum(bests))


def _exact_sides(scene, turned, sides, angles, bests, gap) -> list:
    """The smallest contact rotation of each side on the exact curves, from the polygon's.

    A tooth's polygon root ``a_i`` and its exact root differ by about
    ``gap / s_i``, with ``s_i ~ d_i / a_i`` the clearance's mean slope from
    no rotation to contact; every tooth whose root can then be the smallest
    is solved by Newton on the exact clearance (``Scene.exact_to``; the
    derivative by a 1e-9 rad difference), both sides in one batch per step
    (a refinement's cost is per call more than per pair).
    """
    rows, dirs, rigid, x, side_of = [], [], [], [], []
    for k, ((idx, direction, d), angle, best) in enumerate(zip(sides, angles, bests)):
        if not np.isfinite(best):
            continue
        r = np.array([i for i, a in angle.items() if np.isfinite(a)], dtype=int)
        a = np.array([angle[i] for i in r])
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.where(a > 0, np.maximum(d[r] / a, 1e-12), np.inf)
        j = int(np.argmin(a))
        keep = a - 2.0 * gap / slope <= a[j] + 2.0 * gap / slope[j]
        rows.append(r[keep])
        dirs.append(np.full(int(keep.sum()), direction))
        rigid.append(idx[r[keep]])
        x.append(a[keep].copy())
        side_of.append(np.full(int(keep.sum()), k))
    if not rows:
        return list(bests)
    rows, dirs, rigid, x, side_of = (np.concatenate(v) for v in (rows, dirs, rigid, x, side_of))

    def f(sel, x_):
        r, sh = turned(rows[sel], dirs[sel] * x_)
        return scene.exact_to(r, sh, rigid[sel])[0]

    h = 1e-9
    live = np.arange(len(rows))
    for _ in range(8):
        if live.size == 0:
            break
        both = f(np.concatenate([live, live]), np.concatenate([x[live], x[live] + h]))
        f0, f1 = both[: live.size], both[live.size :]
        step = f0 / np.where(f1 != f0, (f1 - f0) / h, np.inf)
        x[live] -= step
        # 1e-10 mm from contact is ~1e-11 rad of turn on these levers (> 10 mm): far below 1e-3 arcsec
        live = live[(np.abs(f0) > 1e-10) & (np.abs(step) > 1e-13)]
    return [float(x[side_of == k].min()) if np.any(side_of == k) else bests[k] for k in range(len(bests))]
