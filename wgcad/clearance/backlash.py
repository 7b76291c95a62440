"""Backlash (dead travel) at a generator angle: rigid turn of the flexspline between contact either way (docs/models.md 5)."""

from __future__ import annotations

from math import pi

import numpy as np

from ..placement import tooth_pose, transform
from ..plane import rotate
from ..roots import brentq
from .scene import Scene
from .search import fold

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
        keep = np.abs(fold(phi, 2 * pi)) <= pi / scene.n_w + 1e-12
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
    if exact:
        angles, bests = [], []
        for idx, direction, d in sides:
            roots = _polygon_roots(scene, turned, idx, direction, r_max, d, gap)
            best = min(roots.values(), default=np.inf)
            # a tooth needs at least (d - gap) / r_max to touch on the curves: the others cannot beat the best
            angles.append({i: a for i, a in roots.items() if (d[i] - gap) / r_max < best})
            bests.append(best)
        return float(sum(_exact_sides(scene, turned, sides, angles, bests, gap)))
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
            angle[int(i)] = contact_angle(int(i), int(idx[i]), direction)
            best = min(best, angle[int(i)])
        bests.append(best)
        angles.append(angle)
    return float(sum(bests))


def _polygon_roots(scene, turned, idx, direction, r_max, d, gap: float) -> dict:
    """Every tooth's polygon contact rotation (``{tooth: rad}``, inf where none within a rigid pitch), all teeth at once.

    Where the exact curves' rotation is found from it (:func:`_exact_sides`) the polygon root only places the start
    of that search, so it is found to 1e-9 rad, all teeth in one call per step: bracketed from ``d / r_max``
    (doubling until the sign changes), then regula falsi (Illinois), leaving out (inf) the teeth that need more
    than the smallest bracket's end to touch (``d``, less ``gap``, over ``r_max``: the same bound as the polygon
    audit's loop). A pair the polygons overlap but the curves do not starts from no turn (its root reads 0).
    """
    n = len(idx)

    def f(rows, x):
        r, sh = turned(rows, direction * x)
        return scene.clearance_to(r, sh, idx[rows])

    rows = np.arange(n)
    f0 = f(rows, np.zeros(n))
    root = np.where(f0 == 0.0, 0.0, np.inf)
    a, fa = np.zeros(n), f0.copy()
    b = np.sign(f0) * np.maximum(np.abs(f0) / r_max, 1e-12)
    fb = f(rows, b)
    grow = np.nonzero((np.sign(fb) == np.sign(f0)) & (f0 != 0.0))[0]
    while grow.size:
        a[grow], fa[grow] = b[grow], fb[grow]
        b[grow] *= 2.0
        fb[grow] = f(grow, b[grow])
        grow = grow[(np.sign(fb[grow]) == np.sign(f0[grow])) & (np.abs(b[grow]) < scene.gamma_b)]
    live = np.nonzero((np.sign(fb) != np.sign(f0)) & (f0 != 0.0))[0]
    if live.size:
        # every bracket's end bounds its root: a tooth that needs more than the smallest to touch is left out
        best = min(float(np.abs(b[live]).min()), float(root.min()))
        live = live[(d[live] - gap) / r_max < best]
    for _ in range(200):
        if live.size == 0:
            break
        done = (np.abs(b[live] - a[live]) <= 1e-9) | (fb[live] == 0.0)
        root[live[done]] = b[live[done]]
        live = live[~done]
        if live.size == 0:
            break
        c = b[live] - fb[live] * (b[live] - a[live]) / (fb[live] - fa[live])
        fc = f(live, c)
        flip = np.sign(fc) != np.sign(fb[live])  # the root lies between c and b: b becomes the other end
        keep = live[~flip]
        fa[keep] *= 0.5  # Illinois: the end kept twice in a row has its value halved
        a[live[flip]], fa[live[flip]] = b[live[flip]], fb[live[flip]]
        b[live], fb[live] = c, fc
    return {int(i): max(float(root[i]), 0.0) for i in range(n)}


def _exact_sides(scene, turned, sides, angles, bests, gap) -> list:
    """The smallest contact rotation of each side on the exact curves, from the polygon's.

    A tooth's polygon root ``a_i`` and its exact root differ by about
    ``gap / s_i``, with ``s_i ~ d_i / a_i`` the clearance's mean slope from
    no rotation to contact; every tooth whose root can then be the smallest
    is turned towards contact from ``a_i - 2 gap / s_i``, where the teeth
    are apart (:func:`_approach`), both sides in one batch per step (a
    refinement's cost is per call more than per pair); a tooth the batch
    cannot approach starts from its polygon root. Every row then ends
    with Newton on the exact signed figure (:func:`_newton_signed`): the
    approach's last step is only as good as the batch distance near
    contact (on D4 sectored it stopped 1.3e-8 mm short of contact, 8e-10
    rad), and one or two Newton steps from there take it to 1e-10 mm.
    """
    rows, dirs, rigid, x, side_of, slopes = [], [], [], [], [], []
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
        slopes.append(slope[keep])
    if not rows:
        return list(bests)
    rows, dirs, rigid, x, side_of, slopes = (np.concatenate(v) for v in (rows, dirs, rigid, x, side_of, slopes))
    back = 2.0 * gap / slopes
    root = np.full(len(x), np.nan)
    # (a pair touching at no turn has no slope: Newton on the signed figure)
    some = np.isfinite(back)
    root[some] = _approach(scene, turned, rows[some], dirs[some], rigid[some], x[some] - back[some], back[some])
    # every row ends with Newton on the exact signed figure: from an approached root (within ~1e-8 mm of contact,
    # the batch distance's own precision near contact) it takes one or two steps, from a polygon root a few more
    start = np.where(np.isfinite(root), root, x)
    root = _newton_signed(scene, turned, rows, dirs, rigid, start)
    return [float(root[side_of == k].min()) if np.any(side_of == k) else bests[k] for k in range(len(bests))]


def _approach(scene, turned, rows, dirs, rigid, start, back) -> np.ndarray:
    """Each row's contact rotation on the exact curves, approached from the side where the teeth are apart.

    From ``start`` (a turn where the teeth are apart; a row that crosses
    there retreats by ``back``, or is left unsolved where that is 0) Newton
    on the curves' distance ``D(x)`` (:meth:`Scene.apart_to`, its
    derivative by the envelope theorem: the closest points' normal times the
    flexspline point's velocity) aims at a hundredth of the current
    distance, so the teeth stay apart (the step's own error is second order
    in it), until ``D`` is below 1e-4 mm; the root is then one step on. Its
    error is second order in that step where the profiles' relative
    curvature is large, but near-conformal contacts and the normal's error
    (the closest points are ~1e-9 mm apart-accurate) leave up to 1.3e-8 mm
    (D4 sectored), so :func:`_exact_sides` finishes every row by Newton on
    the signed figure (tests/test_refine.py compares the result with Newton
    from the polygon roots on every template to 1e-10 rad). A row
    that crosses the other tooth (``D`` of 0) steps back halfway. NaN where
    a row could not be approached: the batch left its pair unsolved, or its
    distance grows as it turns.
    """
    xi = np.asarray(start, dtype=float).copy()
    root = np.full(len(xi), np.nan)
    x_apart = xi.copy()
    live = np.arange(len(xi))
    for _ in range(30):
        if live.size == 0:
            break
        r, sh = turned(rows[live], dirs[live] * xi[live])
        D, solved, pa, pb = scene.apart_to(r, sh, rigid[live])
        crossed = solved & (D < 1e-10)
        # back halfway to the last apart turn (from the start, as far again)
        c = live[crossed]
        first = xi[c] == x_apart[c]
        x_apart[c[first]] -= back[c[first]]
        c = c[~(first & (back[c] == 0.0))]  # crossing where said to be apart: left unsolved
        xi[c] = 0.5 * (xi[c] + x_apart[c])
        fine = solved & ~crossed
        f = live[fine]
        # the rigid tooth's frame turns with it: the gear axis sits at its origin less its shift
        axis = rotate(-scene.rigid_shift[rigid[f]], -scene.rigid_rot[rigid[f]])
        arm = pa[fine] - axis
        n = (pa[fine] - pb[fine]) / D[fine, None]
        rate = -dirs[f] * (n[:, 0] * -arm[:, 1] + n[:, 1] * arm[:, 0])  # -dD/dx, > 0 approaching
        ok = rate > 0
        close = ok & (D[fine] < 1e-4)
        root[f[close]] = xi[f[close]] + D[fine][close] / rate[close]
        go = ok & ~close
        x_apart[f[go]] = xi[f[go]]
        xi[f[go]] += 0.99 * D[fine][go] / rate[go]
        # unsolved rows and rows moving away from contact are left to the general refinement
        live = np.concatenate([c, f[go]])
    return root


def _newton_signed(scene, turned, rows, dirs, rigid, x) -> np.ndarray:
    """Contact rotations by Newton on the exact signed figure (:meth:`Scene.exact_to`; the derivative by a 1e-9 rad
    difference), all rows in one batch per step, from the polygon roots ``x``."""
    x = x.copy()

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
    return x
