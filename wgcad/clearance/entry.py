"""Entry into engagement: where a tooth's tip crosses the rigid tip circle, and its gaps by the working and non-working edges there, Delta of [S1] (docs/models.md 5).

A tooth enters engagement when its tip crosses the rigid tip circle on the
entry side: from there on the flanks overlap radially and the pair has a
gap by each edge, the distance along the contact normal between the
flexspline tooth and the rigid tooth it faces on that side (working or
non-working, the gaps ``delta_k`` of [S1], computed here on the exact
curves). The entering tooth's gaps either rise from the crossing or dip
first while its tip passes the rigid tooth's tip (the pinch) before the
flanks take over. The *entry gap* Delta of a passage is the smallest gap
over that entry: the pinch where there is one, else the gap at the
crossing; over the sections (and waves, and load states) the smallest is
the drive's Delta. The fall of the gaps from there into flank engagement
near the major axis is not the entry.

Every function takes the passages as a pose function
``poses(phi (N,), k (N,)) -> (rot (N,), shift (N, 2))`` (``phi`` the signed
tooth angle from the major axis, ``k`` the passage: a section of the
analytic law, or a section and wave of a loaded state), so the no-load
audit, the load audit and the imperfect audit share one definition.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from ..placement import transform
from .scene import Scene, classify

__all__ = [
    "EntryPassage",
    "EDGES",
    "section_poses",
    "crossings",
    "edge_gaps",
    "entry_passages",
    "smallest",
    "entry_crossings",
    "entry_gap",
    "entry_pinch",
    "lipschitz_min",
    "PINCH_STEP",
]

#: the two edges of a tooth pair, in the order of every ``(K, 2)`` array here
EDGES = ("working", "non-working")

#: grid step (rad) on which the gaps are followed from the crossing inward: 0.25 deg, a quarter of the
#: narrowest pinch seen on the templates (the pinch lies 0.2-1 deg after the crossing)
PINCH_STEP = np.deg2rad(0.25)
#: the tip passage: radial overlap of the tips (flexspline tip circle past the rigid tip circle) within this
#: many modules either way of the crossing. The tip corners pass each other there: the templates' pinches lie
#: at -0.06 to +0.17 modules (D2 as first templated: the corners closest just before the crossing; D3: a tip
#: corner cutting into the rigid flank); the gaps beyond are the flanks'
TIP_BAND = 0.3
#: nested exact grids that close in on a pinch: 17 points each an eighth as wide as the last (8^4 = 4096 times
#: finer than the bracket; 1/256 left a pinch 0.015 um high)
_NEST, _NEST_PTS = 4, 17


@dataclass(frozen=True, slots=True)
class EntryPassage:
    """The entry of one passage (mm, rad inside).

    Attributes
    ----------
    index : int
        The passage ``k`` of the pose function.
    crossing : float
        Signed tooth angle where the tip crosses the rigid tip circle; NaN when the tips never cross.
    crossing_gaps : (2,) float
        Gaps by the working and the non-working edge at the crossing (:data:`EDGES` order).
    pinch : tuple of 2
        Per edge ``(gap, tooth angle)`` of the pinch, or None where the gap does not dip after the crossing.
    delta : float
        The entry gap Delta of this passage: the smallest of the crossing gaps and the pinches.
    delta_phi : float
        Where it lies (signed tooth angle).
    delta_edge : str
        ``"working"`` or ``"non-working"``.
    delta_kind : str
        ``"pinch"`` or ``"crossing"``.
    """

    index: int
    crossing: float
    crossing_gaps: tuple
    pinch: tuple
    delta: float
    delta_phi: float
    delta_edge: str
    delta_kind: str


def section_poses(scene: Scene, zs: list):
    """The pose function of the analytic law's sections ``zs`` (passage ``k`` = section ``zs[k]``)."""
    return lambda phi, k: scene.pose_sections(np.asarray(phi, dtype=float), np.asarray(k), zs)


def crossings(scene: Scene, poses, K: int) -> np.ndarray:
    """Signed tooth angle of each passage's entry crossing (NaN where the tips never cross), ``(K,)``.

    The tip arc's radial gap to the rigid tip circle is exact
    (:meth:`Scene.tip_radial`); it is sampled over the entry half-wave on a
    1 deg grid, the outermost change from radial overlap (near the major
    axis) to separation bracketed, the bracket shrunk 32-fold twice on
    vectorised grids, and the root of the chord across the last one taken
    (the gap is smooth there: within ~1e-10 rad, which moves a clearance by
    less than 1e-9 mm).
    """
    sgn = scene.entry_sign
    half = pi / scene.n_w
    grid = np.linspace(0.0, half, int(round(np.rad2deg(half))) + 1)
    n = len(grid)
    ks = np.arange(K)

    def f(t, k):
        return scene.tip_radial(*poses(sgn * t, k))

    vals = f(np.tile(grid, K), np.repeat(ks, n)).reshape(K, n)
    lo = np.full(K, np.nan)
    hi = np.full(K, np.nan)
    for k in range(K):
        cross = np.nonzero((vals[k, :-1] <= 0) & (vals[k, 1:] > 0))[0]
        if cross.size:  # the outermost: a loaded rim can wrinkle the tip path near the axis
            lo[k], hi[k] = grid[cross[-1]], grid[cross[-1] + 1]
    ok = np.nonzero(np.isfinite(lo))[0]
    out = np.full(K, np.nan)
    if not ok.size:
        return out
    steps = 33
    flo = fhi = None
    for _ in range(2):
        g = lo[ok][:, None] + (hi[ok] - lo[ok])[:, None] * np.linspace(0.0, 1.0, steps)[None, :]
        v = f(g.ravel(), np.repeat(ok, steps)).reshape(len(ok), steps)
        # the last overlap before separation within the bracket
        last = steps - 1 - np.argmax((v <= 0)[:, ::-1], axis=1)
        last = np.minimum(last, steps - 2)
        rows = np.arange(len(ok))
        lo[ok], hi[ok] = g[rows, last], g[rows, last + 1]
        flo, fhi = v[rows, last], v[rows, last + 1]
    out[ok] = sgn * (lo[ok] - flo * (hi[ok] - lo[ok]) / (fhi - flo))
    return out


def edge_index(scene: Scene, rot, shift):
    """Rigid tooth faced by the working and by the non-working edge of each placed tooth, ``(N,)`` each."""
    lo, up, _ = scene.neighbours(shift, rot)
    return (up, lo) if scene.working == "upper" else (lo, up)


def edge_gaps(scene: Scene, rot: np.ndarray, shift: np.ndarray, exact: bool = True, edges=None) -> np.ndarray:
    """Gaps ``(N, 2)`` by the working and the non-working edge of teeth at poses ``(rot, shift)`` (mm, negative: overlap depth).

    Each is the signed clearance between the tooth and the rigid tooth on
    that side: on the exact curves (``exact``), else on the outlines.
    ``edges`` ``(N,)`` (0 working, 1 non-working): only that edge of each
    tooth, ``(N,)`` (each pair measured as in the two-edge call).
    """
    rot = np.atleast_1d(rot)
    shift = np.atleast_2d(shift)
    jw, jn = edge_index(scene, rot, shift)
    if edges is not None:
        j = np.where(np.asarray(edges) == 0, jw, jn)
        return scene.exact_to(rot, shift, j)[0] if exact else scene.clearance_to(rot, shift, j)
    out = np.empty((len(rot), 2))
    if exact:
        val = scene.exact_to(np.concatenate([rot, rot]), np.concatenate([shift, shift]), np.concatenate([jw, jn]))[0]
        out[:, 0], out[:, 1] = val[: len(rot)], val[len(rot) :]
    else:
        out[:, 0] = scene.clearance_to(rot, shift, jw)
        out[:, 1] = scene.clearance_to(rot, shift, jn)
    return out


def _bands(scene: Scene, poses, starts: np.ndarray, module: float):
    """Each passage's tip passage: the tooth angles (unsigned, outward first) where the tips overlap radially by
    at most :data:`TIP_BAND` modules either way, the contiguous run around the crossing on a :data:`PINCH_STEP` grid."""
    sgn = scene.entry_sign
    half = pi / scene.n_w
    grid = np.arange(half, -1e-12, -PINCH_STEP)
    ok = np.nonzero(np.isfinite(starts))[0]
    if ok.size:
        K = len(ok)
        n = len(grid)
        depth = -scene.tip_radial(*poses(sgn * np.tile(grid, K), np.repeat(ok, n))).reshape(K, n)
    bands = [np.zeros(0)] * len(starts)
    for j, k in enumerate(ok):
        inside = np.abs(depth[j]) <= TIP_BAND * module
        c = int(np.argmin(np.abs(grid - starts[k])))
        if not inside[c]:
            continue
        a = c
        while a > 0 and inside[a - 1]:
            a -= 1
        b = c
        while b < len(grid) - 1 and inside[b + 1]:
            b += 1
        bands[k] = grid[a : b + 1]
    return bands


def _walk(scene: Scene, poses, starts: np.ndarray, noise: float):
    """The pinch of each passage and edge: a minimum of the edge gap inside the tip passage (:func:`_bands`) that
    the gap rises from again toward the major axis by more than ``noise`` (a dip the chord tolerance can neither
    have made nor hidden), followed on the outlines.

    A gap that falls through the whole tip passage runs into flank engagement, and one that only rises from
    the outer end of the passage has its smallest value before the tips meet: neither has a pinch.

    Returns
    -------
    list over passages of 2 items: None, or ``(t_lo, t_hi)`` the bracket (unsigned tooth angles) of the pinch.
    """
    sgn = scene.entry_sign
    bands = _bands(scene, poses, starts, scene.drive.design.drive.module)
    K = len(starts)
    result = [[None, None] for _ in range(K)]
    live = [k for k in range(K) if len(bands[k]) >= 3]
    if not live:
        return result
    phi = np.concatenate([bands[k] for k in live])
    kk = np.concatenate([np.full(len(bands[k]), k) for k in live])
    g = edge_gaps(scene, *poses(sgn * phi, kk), exact=False)
    at = 0
    for k in live:
        n = len(bands[k])
        gk = g[at : at + n]
        at += n
        for e in (0, 1):
            v = gk[:, e]
            i = int(np.argmin(v))
            if 0 < i and v[i:].max() > v[i] + noise:
                result[k][e] = _bracket(bands[k], v, i, noise)
    return result


def _bracket(grid, v, i, noise):
    """The run of grid points within ``noise`` of the minimum ``v[i]``, and one more each side: ``(t_lo, t_hi)``."""
    a = i
    while a > 0 and v[a - 1] <= v[i] + noise:
        a -= 1
    b = i
    while b < len(v) - 1 and v[b + 1] <= v[i] + noise:
        b += 1
    a, b = max(a - 1, 0), min(b + 1, len(grid) - 1)
    return (min(grid[a], grid[b]), max(grid[a], grid[b]))


def _refine(scene: Scene, poses, jobs, exact: bool):
    """The minimum of each job's edge gap in its bracket: nested grids, all jobs in one call per round.

    ``jobs``: list of ``(k, edge, t_lo, t_hi)``. The first grid spans the
    whole bracket (the polygons' minimum can sit elsewhere in it), each next
    one an eighth as wide around the best so far. Returns ``[(gap, t)]``.
    """
    sgn = scene.entry_sign
    if not jobs:
        return []
    J = len(jobs)
    k = np.array([j[0] for j in jobs])
    e = np.array([j[1] for j in jobs])
    lo = np.array([j[2] for j in jobs])
    hi = np.array([j[3] for j in jobs])
    c = 0.5 * (lo + hi)
    w = 0.5 * (hi - lo)
    best = np.full(J, np.inf)
    best_t = c.copy()
    u = np.linspace(-1.0, 1.0, _NEST_PTS)
    for _ in range(_NEST):
        t = np.clip(c[:, None] + w[:, None] * u[None, :], lo[:, None], hi[:, None])
        rot, shift = poses(sgn * t.ravel(), np.repeat(k, _NEST_PTS))
        g = edge_gaps(scene, rot, shift, exact=exact, edges=np.repeat(e, _NEST_PTS)).reshape(J, _NEST_PTS)
        j = np.argmin(g, axis=1)
        gv = g[np.arange(J), j]
        better = gv < best
        best = np.where(better, gv, best)
        best_t = np.where(better, t[np.arange(J), j], best_t)
        c = best_t
        w = w / 8.0
    return list(zip(best.tolist(), best_t.tolist()))


def entry_passages(scene: Scene, poses, K: int, exact: bool = True) -> list[EntryPassage]:
    """The entry of every passage ``k < K`` of a pose function (module docstring, docs/models.md 5).

    The crossing (:func:`crossings`), the gaps by both edges there, the
    pinch of each edge (followed on polygons, refined by nested grids, on
    the exact curves with ``exact``), and Delta.
    """
    sgn = scene.entry_sign
    phi_c = crossings(scene, poses, K)
    ok = np.nonzero(np.isfinite(phi_c))[0]
    cg = np.full((K, 2), np.nan)
    if ok.size:
        cg[ok] = edge_gaps(scene, *poses(phi_c[ok], ok), exact=exact)
    noise = 2.0 * scene.chord_gap
    brackets = _walk(scene, poses, np.abs(phi_c), noise)
    jobs = [(k, e, *brackets[k][e]) for k in range(K) for e in (0, 1) if brackets[k][e] is not None]
    found = dict(zip([(j[0], j[1]) for j in jobs], _refine(scene, poses, jobs, exact)))
    out = []
    for k in range(K):
        if not np.isfinite(phi_c[k]):
            out.append(
                EntryPassage(k, float("nan"), (float("nan"),) * 2, (None, None), float("nan"), float("nan"), "", "")
            )
            continue
        pinch = tuple((found[(k, e)][0], sgn * found[(k, e)][1]) if (k, e) in found else None for e in (0, 1))
        cands = [(float(cg[k, e]), float(phi_c[k]), EDGES[e], "crossing") for e in (0, 1)]
        cands += [(p[0], p[1], EDGES[e], "pinch") for e, p in enumerate(pinch) if p is not None]
        d = min(cands, key=lambda c: c[0])
        out.append(EntryPassage(k, float(phi_c[k]), (float(cg[k, 0]), float(cg[k, 1])), pinch, *d))
    return out


def smallest(passages: list[EntryPassage]) -> EntryPassage | None:
    """The passage with the smallest Delta (None when no tip crosses)."""
    live = [p for p in passages if np.isfinite(p.delta)]
    return min(live, key=lambda p: p.delta) if live else None


# --------------------------------------------------------------------------------------------------
# the analytic law's sections (the no-load audit and the imperfect audit's perfect twin)


def entry_crossings(scene: Scene, zs: list, exact: bool = True) -> list[tuple[float, float]]:
    """Per section of the analytic law: ``(gap mm, phi rad)`` at the entry crossing (the smaller of the two edges)."""
    poses = section_poses(scene, zs)
    phi_c = crossings(scene, poses, len(zs))
    out = [(float("nan"), float("nan"))] * len(zs)
    ok = np.nonzero(np.isfinite(phi_c))[0]
    if ok.size:
        g = edge_gaps(scene, *poses(phi_c[ok], ok), exact=exact).min(axis=1)
        for j, k in enumerate(ok):
            out[k] = (float(g[j]), float(phi_c[k]))
    return out


def entry_gap(scene: Scene, z) -> tuple[float, float]:
    """:func:`entry_crossings` of one section: ``(gap mm, phi rad)``."""
    return entry_crossings(scene, [z])[0]


def entry_pinch(scene: Scene, crossings_, tol: float | None = None, exact: bool = True):
    """The smallest pinch over sections of the analytic law, as ``(gap mm, phi rad, z, location)``, or None.

    ``crossings_``: list of ``(phi_star, z)`` (the sections to follow). ``tol`` is unused (kept for callers:
    the nested grids close in to 1/4096 of the bracket).
    """
    zs = [z for _, z in crossings_]
    passages = entry_passages(scene, section_poses(scene, zs), len(zs), exact=exact)
    best = None
    for p in passages:
        for e, pin in enumerate(p.pinch):
            if pin is not None and (best is None or pin[0] < best[0]):
                best = (pin[0], pin[1], zs[p.index], e)
    if best is None:
        return None
    c, phi, z, e = best
    return c, phi, z, location(scene, phi, z, e)


def location(scene: Scene, phi: float, z, edge: int) -> str:
    """Where on the flexspline tooth at ``phi`` (analytic law, section ``z``) its gap by ``edge`` is measured: tip, root or flank."""
    rot, shift = scene.pose(np.array([phi]), z)
    jw, jn = edge_index(scene, rot, shift)
    j = int((jw if edge == 0 else jn)[0])
    pts = transform(scene.flex_local, rot, shift)[0]
    return classify(scene, pts, j, phi, z)


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
