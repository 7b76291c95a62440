"""Entry crossing (tip circle meets the rigid tip circle) and the pinch after it, wherever they lie (docs/models.md 5)."""

from __future__ import annotations

from math import pi

import numpy as np

from ..placement import transform
from .scene import Scene, _classify, tooth_clearance, tooth_clearance_sections

__all__ = ["entry_crossings", "entry_gap", "lipschitz_min", "entry_pinch", "PINCH_STEP"]


def entry_crossings(scene: Scene, zs: list, exact: bool = True) -> list[tuple[float, float]]:
    """Entry gap (docs/models.md 5) of each section: the clearance when the tooth's tip crosses the rigid tip circle on the entry side.

    The tip arc's radial gap to the rigid tip circle is exact
    (:meth:`Scene.tip_radial`); it is sampled over the whole entry half-wave
    (1 deg grid), the first crossing from radial overlap (near the major
    axis) to separation is bracketed, shrunk 32-fold twice by vectorised
    grids, and the root of the chord across the last bracket taken (f is
    smooth there: within ~1e-10 rad, the clearance moves by less than
    ``V * 1e-10``, ~3e-10 mm). The gap itself is refined on the exact curves
    (``exact``).

    Returns
    -------
    list of ``(gap mm, phi rad)`` per section (NaN where the tips never cross).
    """
    sgn = scene.entry_sign
    half = pi / scene.n_w
    m = len(zs)

    def f(p, zi):
        rot, shift = scene.pose_sections(sgn * p, zi, zs)
        return scene.tip_radial(rot, shift)

    grid = np.linspace(0.0, half, int(round(np.rad2deg(half))) + 1)
    n = len(grid)
    vals = f(np.tile(grid, m), np.repeat(np.arange(m), n)).reshape(m, n)
    # radial overlap near the major axis (f <= 0), separation toward the minor axis (f > 0)
    lo = np.full(m, np.nan)
    hi = np.full(m, np.nan)
    for k in range(m):
        cross = np.nonzero((vals[k, :-1] <= 0) & (vals[k, 1:] > 0))[0]
        if cross.size:
            lo[k], hi[k] = grid[cross[0]], grid[cross[0] + 1]
    ok = np.nonzero(np.isfinite(lo))[0]
    steps = 33
    flo = fhi = None
    for _ in range(2):  # 1 deg / 32^2: brackets of ~1.7e-5 rad
        if not ok.size:
            break
        g = lo[ok][:, None] + (hi[ok] - lo[ok])[:, None] * np.linspace(0.0, 1.0, steps)[None, :]
        v = f(g.ravel(), np.repeat(ok, steps)).reshape(len(ok), steps)
        first = np.maximum(np.argmax(v > 0, axis=1), 1)  # first grid point past the crossing
        rows = np.arange(len(ok))
        lo[ok], hi[ok] = g[rows, first - 1], g[rows, first]
        flo, fhi = v[rows, first - 1], v[rows, first]
    out = [(float("nan"), float("nan"))] * m
    if ok.size:
        p_star = lo[ok] - flo * (hi[ok] - lo[ok]) / (fhi - flo)
        gaps = tooth_clearance_sections(scene, sgn * p_star, ok, zs, exact=exact)
        for j, k in enumerate(ok):
            out[k] = (float(gaps[j]), float(sgn * p_star[j]))
    return out


def entry_gap(scene: Scene, z) -> tuple[float, float]:
    """:func:`entry_crossings` of one section: ``(gap mm, phi rad)``."""
    return entry_crossings(scene, [z])[0]


#: cells of :func:`lipschitz_min` split into this many per round
SPLIT = 4


def lipschitz_min(f, lo: np.ndarray, hi: np.ndarray, V: np.ndarray, tol: float, n0: int = 25):
    """Global minimum of several 1D functions at once, each on its own interval, from a Lipschitz bound.

    ``f(x, k)`` evaluates function ``k[i]`` at ``x[i]`` (vectorised). Every
    interval starts as a grid of ``n0`` points; a cell ``[a, b]`` cannot hold a
    value below ``(f(a) + f(b))/2 - V (b - a)/2``, so cells whose bound is not
    below the best value found (less ``tol``) are dropped and the rest split
    in :data:`SPLIT`, until none is left. The result is within ``tol`` of the smallest
    value of all the functions.

    Returns
    -------
    (value, x, k) of the smallest point found.
    """
    m = len(lo)
    xs = np.concatenate([np.linspace(lo[k], hi[k], n0) for k in range(m)])
    ks = np.repeat(np.arange(m), n0)
    vs = f(xs, ks)
    i = int(np.argmin(vs))
    best = (float(vs[i]), float(xs[i]), int(ks[i]))
    same = ks[:-1] == ks[1:]
    a, b, fa, fb, kc = xs[:-1][same], xs[1:][same], vs[:-1][same], vs[1:][same], ks[:-1][same]
    for _ in range(60):
        lb = 0.5 * (fa + fb) - V[kc] * (b - a) / 2
        keep = lb < best[0] - tol
        if not keep.any():
            break
        a, b, fa, fb, kc = a[keep], b[keep], fa[keep], fb[keep], kc[keep]
        t = np.arange(1, SPLIT) / SPLIT
        xi = a[:, None] + (b - a)[:, None] * t[None, :]  # (C, SPLIT-1)
        vi = f(xi.ravel(), np.repeat(kc, SPLIT - 1)).reshape(xi.shape)
        j = np.unravel_index(int(np.argmin(vi)), vi.shape)
        if vi[j] < best[0]:
            best = (float(vi[j]), float(xi[j]), int(kc[j[0]]))
        xs_ = np.concatenate([a[:, None], xi, b[:, None]], axis=1)
        vs_ = np.concatenate([fa[:, None], vi, fb[:, None]], axis=1)
        a, b = xs_[:, :-1].ravel(), xs_[:, 1:].ravel()
        fa, fb = vs_[:, :-1].ravel(), vs_[:, 1:].ravel()
        kc = np.repeat(kc, SPLIT)
    return best


#: grid step (rad) on which the entry pinch is looked for: 0.25 deg, a quarter of the narrowest
#: pinch seen on the templates (D1: 0.85 deg from the crossing to the pinch)
PINCH_STEP = np.deg2rad(0.25)


def entry_pinch(scene: Scene, crossings, tol: float | None = None, exact: bool = True):
    """The pinch (docs/models.md 5): the first local minimum of the clearance after the entry crossing, wherever it lies.

    Each section's clearance is followed from its own crossing toward the
    major axis on a :data:`PINCH_STEP` grid up to the major axis; the first
    minimum of the smallest over the sections that the clearance rises
    from again by more than the polygons' noise is bracketed (the grid
    points within that noise of it, and one more each side) and found
    within ``tol`` on the polygons
    (:func:`lipschitz_min` with :meth:`Scene.speed_bound`), then refined on
    the exact curves by nested grids (``exact``).

    Parameters
    ----------
    crossings : list of (phi_star, z)
    tol : float, optional
        Default a tenth of the chord tolerance.

    Returns ``(clearance mm, phi rad, z, location)``, or None when the
    clearance falls without a local minimum all the way to the major axis
    (no pinch: the tip runs straight into flank engagement).
    """
    tol = 0.1 * scene.drive.tol if tol is None else tol
    zs = [z for _, z in crossings]
    sgn = scene.entry_sign
    starts = np.array([abs(p) for p, _ in crossings])
    n = int(np.ceil(starts.max() / PINCH_STEP)) + 1
    grid = np.linspace(0.0, 1.0, n)[None, :] * starts[:, None]  # (m, n): 0 .. crossing, per section
    m = len(zs)
    vals = tooth_clearance_sections(scene, sgn * grid.ravel(), np.repeat(np.arange(m), n), zs).reshape(m, n)
    c = vals.min(axis=0)[::-1]  # smallest over sections, walking from the crossing toward the axis
    phis = grid[:, ::-1]
    # the first minimum the clearance rises from again by more than the polygons' noise (twice the
    # polygon-curve difference): a dip the chord tolerance cannot have made or hidden
    noise = 2.0 * scene.chord_gap
    first = None
    m_i = 0
    for i in range(1, n):
        if c[i] < c[m_i]:
            m_i = i
        elif c[i] > c[m_i] + noise and m_i > 0:
            first = m_i
            break
    if first is None:
        return None
    # bracket: the run of grid points within the noise of the minimum, and one more each side
    a_i = first
    while a_i > 0 and c[a_i - 1] <= c[first] + noise:
        a_i -= 1
    b_i = first
    while b_i < n - 1 and c[b_i + 1] <= c[first] + noise:
        b_i += 1
    a_i, b_i = max(a_i - 1, 0), min(b_i + 1, n - 1)
    lo = np.minimum(phis[:, a_i], phis[:, b_i])
    hi = np.maximum(phis[:, a_i], phis[:, b_i])
    V = np.array([scene.speed_bound(sgn * np.linspace(a, b, 9), z) for a, b, z in zip(lo, hi, zs)])
    c_min, p_min, k = lipschitz_min(lambda x, kk: tooth_clearance_sections(scene, sgn * x, kk, zs), lo, hi, V, tol)
    if exact:
        # the exact curves' minimum in the bracket: nested 17-point grids, each an eighth of the last,
        # the first across the whole bracket (the polygons' minimum can sit elsewhere in it); a call
        # costs about the same for 9 or 17 points, so fewer, wider rounds
        w = 0.5 * (hi[k] - lo[k])
        p_c = 0.5 * (hi[k] + lo[k])
        c_min = np.inf
        for _ in range(4):  # 8^4 = 4096 times finer than the bracket (1/256 left D1's pinch 0.015 um high)
            g = np.clip(p_c + np.linspace(-w, w, 17), lo[k], hi[k])
            v = tooth_clearance_sections(scene, sgn * g, np.full(17, k), zs, exact=True)
            j = int(np.argmin(v))
            if v[j] < c_min:
                c_min, p_c = float(v[j]), float(g[j])
            w /= 8.0
        p_min = p_c
    z_min = zs[k]
    p_min = sgn * p_min
    det = tooth_clearance(scene, np.array([p_min]), z_min)
    side = "lower" if det["lower"][0] <= det["upper"][0] else "upper"
    rot, shift = scene.pose(np.array([p_min]), z_min)
    pts = transform(scene.flex_local, rot, shift)[0]
    loc = _classify(scene, pts, int(det["lo" if side == "lower" else "up"][0]), p_min, z_min)
    return c_min, p_min, z_min, loc
