"""Stress concentration at the flexspline's tooth roots when the rim bends: a plane-strain finite-element model of a toothed sector (docs/models.md 10.2).

The rim between the bore and the toothed boundary, ``pitches`` teeth long and
cut at the middle of a space at both ends, is bent by turning its end faces
against each other (pure bending: the faces stay plane, no net normal
force). ``K`` is the largest tangential stress on the middle pitch's free
boundary over the stress a plain rim of the thickness under the teeth takes
at its surface when bent to the same curvature, ``E' (h1/2) dkappa``. Linear
triangles on a mesh graded towards the middle pitch's roots, the boundary
stress recovered by a least-squares fit of the element stresses around each
boundary node (Zienkiewicz and Zhu's patch recovery). numpy, scipy and
shapely only; tests/fe_root_reference.py checks it with quadratic elements
of scikit-fem on a mesh of its own.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np
import shapely

__all__ = ["RootConcentration", "root_concentration"]


@dataclass(frozen=True, slots=True)
class RootConcentration:
    """The tooth root's stress concentration in rim bending.

    Attributes
    ----------
    kt : float
        Largest tangential stress on the toothed surface over ``E' (h1/2) dkappa``.
    angle : float
        Polar angle of the peak from the tooth centre, rad (the roots are symmetric: the peak on one side).
    radius : float
        Radius of the peak, mm.
    nodes : int
        Nodes of the mesh.
    h_min : float
        Element size at the roots, mm.
    """

    kt: float
    angle: float
    radius: float
    nodes: int
    h_min: float


def _dense_period(gear, step: float) -> np.ndarray:
    """One pitch of the toothed boundary sampled on its exact pieces at most ``step`` apart (mm): the outline's
    polyline, sampled to the chord tolerance, turns by several degrees at its vertices on the tight root curves, and
    linear elements see each such corner as a notch of its own."""
    if not gear.pieces:
        return np.asarray(gear.period, dtype=float)
    out = []
    for p in gear.pieces:
        n = max(2, int(np.ceil(p.length() / step)) + 1)
        pts = p.point(np.linspace(p.t0, p.t1, n))
        out.append(pts if not out else pts[1:])
    return np.concatenate(out)


def _sector_boundary(gear, bore: float, pitches: int, step: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The sector's outline (counter-clockwise) as a closed polyline, the indices of its four corners (where the
    end faces meet the toothed side and the bore) and its half angle."""
    z = gear.spec.z
    half = pitches * pi / z
    period = _dense_period(gear, step)
    parts = []
    for k in range(-(pitches // 2), pitches // 2 + 1):
        a = 2.0 * pi * k / z
        c, s = np.cos(a), np.sin(a)
        p = period @ np.array([[c, s], [-s, c]])
        parts.append(p if not parts else p[1:])
    teeth = np.concatenate(parts)
    ang = np.arctan2(teeth[:, 1], teeth[:, 0])
    if ang[0] > ang[-1]:
        teeth = teeth[::-1]
    arc = np.linspace(half, -half, max(16, int(np.ceil(2 * half * bore / 0.05))))
    bore_pts = bore * np.column_stack([np.cos(arc), np.sin(arc)])
    pts = np.concatenate([teeth, bore_pts])
    n = len(pts)
    corners = np.array([0, len(teeth) - 1, len(teeth), n - 1])
    area = 0.5 * np.sum(pts[:, 0] * np.roll(pts[:, 1], -1) - np.roll(pts[:, 0], -1) * pts[:, 1])
    if area < 0:
        pts, corners = pts[::-1], n - 1 - corners
    return pts, np.sort(corners), half


class _GradedSize:
    """The mesh's element size at points: ``h_min`` at the roots' points, growing by a quarter of the distance
    from them, at most ``h_max``."""

    def __init__(self, roots: np.ndarray, h_min: float, h_max: float):
        from scipy.spatial import cKDTree

        self.roots = np.asarray(roots, dtype=float)
        self.tree = cKDTree(self.roots)
        self.h_min, self.h_max = float(h_min), float(h_max)

    def __call__(self, P) -> np.ndarray:
        d, _ = self.tree.query(np.atleast_2d(P))
        return np.minimum(self.h_max, self.h_min + 0.25 * d)

    def near(self, h: float) -> tuple:
        """A box ``(x0, y0, x1, y1)`` holding every point whose size is below ``h``."""
        reach = 4.0 * max(h - self.h_min, 0.0)
        lo = self.roots.min(axis=0) - reach
        hi = self.roots.max(axis=0) + reach
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def _resample(pts: np.ndarray, size) -> np.ndarray:
    """Points along the closed polyline ``pts`` at spacing ``size(p)`` (every vertex where the outline turns kept)."""
    out = []
    n = len(pts)
    hs = size(pts)  # the size at every vertex in one query (a segment takes the smaller of its ends')
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        out.append(a)
        L = float(np.hypot(*(b - a)))
        h = float(min(hs[i], hs[(i + 1) % n]))
        k = int(np.ceil(L / h))
        if k > 1:
            t = np.arange(1, k)[:, None] / k
            out.extend(a + t * (b - a))
    return np.asarray(out)


def _thin_polyline(pts: np.ndarray, size, corners) -> np.ndarray:
    """Drop vertices of a closed polyline closer than half the local size to the last kept one (outlines are
    sampled to the chord tolerance, far finer than the mesh); the ``corners`` are always kept."""
    keep = [0]
    h = size(pts)
    corners = set(int(c) for c in corners)
    for i in range(1, len(pts)):
        if i in corners:
            if keep[-1] not in corners and np.hypot(*(pts[i] - pts[keep[-1]])) < 0.5 * h[i]:
                keep[-1] = i
            else:
                keep.append(i)
        elif np.hypot(*(pts[i] - pts[keep[-1]])) >= 0.5 * h[i]:
            keep.append(i)
    return pts[keep]


def _interior(poly, size, h_max: float, boundary: np.ndarray) -> np.ndarray:
    """Graded interior points: offset rows of spacing ``h_max / 2^L`` kept where the local size asks for that level,
    away from the boundary."""
    from scipy.spatial import cKDTree

    x0, y0, x1, y1 = poly.bounds
    tree = cKDTree(boundary)
    out = []
    s = h_max
    for level in range(12):
        ys = np.arange(y0, y1 + s, s * np.sqrt(3) / 2)
        xs = np.arange(x0, x1 + s, s)
        rows = np.arange(len(ys))
        if level:
            # a finer level keeps only points whose size is below 2 s, i.e. near the roots: the rows and columns
            # of the same lattice that can hold them (the others' size is >= 2 s and they were dropped anyway)
            bx0, by0, bx1, by1 = size.near(2.0 * s)
            rows = rows[(ys >= by0 - s) & (ys <= by1 + s)]
            xs = xs[(xs >= bx0 - s) & (xs <= bx1 + s)]
        X, Y = np.meshgrid(xs, ys[rows])
        X = X + 0.5 * s * (rows % 2)[:, None]
        P = np.column_stack([X.ravel(), Y.ravel()])
        h = size(P)
        lvl = (h < 2 * s) & (h >= s) if level else h >= s
        P, h = P[lvl], h[lvl]
        if len(P):
            P = P[shapely.contains_xy(poly, P[:, 0], P[:, 1])]
            h = size(P)
            d, _ = tree.query(P)
            out.append(P[d > 0.6 * h])
        s *= 0.5
        if s < 0.5 * size(boundary).min():
            break
    return np.concatenate(out) if out else np.empty((0, 2))


def _mesh(pts_outline: np.ndarray, size, h_max: float, corners):
    from scipy.spatial import Delaunay

    boundary = _resample(_thin_polyline(pts_outline, size, corners), size)
    poly = shapely.Polygon(pts_outline)
    nodes = np.concatenate([boundary, _interior(poly, size, h_max, boundary)])
    tri = Delaunay(nodes).simplices
    c = nodes[tri].mean(axis=1)
    keep = shapely.contains_xy(poly, c[:, 0], c[:, 1])
    tri = tri[keep]
    p = nodes[tri]
    area = 0.5 * (
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1])
    )
    tri = tri[area > 1e-12 * h_max**2]
    return nodes, tri, len(boundary)


def _stiffness(nodes, tri, E: float, nu: float):
    """Plane-strain stiffness of linear triangles, and the strain-displacement matrices ``(T, 3, 6)``."""
    from scipy.sparse import coo_matrix

    p = nodes[tri]
    x, y = p[..., 0], p[..., 1]
    b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
    c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
    A = 0.5 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    B = np.zeros((len(tri), 3, 6))
    B[:, 0, 0::2] = b
    B[:, 1, 1::2] = c
    B[:, 2, 0::2] = c
    B[:, 2, 1::2] = b
    B /= (2.0 * A)[:, None, None]
    f = E / ((1 + nu) * (1 - 2 * nu))
    D = f * np.array([[1 - nu, nu, 0], [nu, 1 - nu, 0], [0, 0, 0.5 - nu]])
    Ke = np.einsum("tki,kl,tlj,t->tij", B, D, B, A)
    dof = np.stack([2 * tri, 2 * tri + 1], axis=2).reshape(len(tri), 6)
    rows = np.repeat(dof, 6, axis=1).ravel()
    cols = np.tile(dof, (1, 6)).ravel()
    n = 2 * len(nodes)
    K = coo_matrix((Ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    return K, B, D, dof, A


def _end_transform(nodes, half: float, r_m: float, dalpha: float, tol: float):
    """``u = T q + u0``: the left face held normal to itself (one node also radially), the right face turned by
    ``dalpha`` about ``r_m`` plus a free shift ``a`` common to its nodes (no net normal force)."""
    from scipy.sparse import coo_matrix

    ang = np.arctan2(nodes[:, 1], nodes[:, 0])
    rho = np.hypot(nodes[:, 0], nodes[:, 1])
    left = np.abs(ang + half) < tol
    right = np.abs(ang - half) < tol
    n = len(nodes)
    rows, cols, vals = [], [], []
    u0 = np.zeros(2 * n)
    q = 0
    anchor = int(np.flatnonzero(left)[np.argmin(rho[left])])
    for i in range(n):
        if left[i] or right[i]:
            a = -half if left[i] else half
            er = np.array([np.cos(a), np.sin(a)])
            et = np.array([-np.sin(a), np.cos(a)])
            if i != anchor:
                rows += [2 * i, 2 * i + 1]
                cols += [q, q]
                vals += [er[0], er[1]]
                q += 1
            if right[i]:
                u0[2 * i : 2 * i + 2] = et * dalpha * (rho[i] - r_m)
        else:
            rows += [2 * i, 2 * i + 1]
            cols += [q, q + 1]
            vals += [1.0, 1.0]
            q += 2
    shift = q
    for i in np.flatnonzero(right):
        et = np.array([-np.sin(half), np.cos(half)])
        rows += [2 * i, 2 * i + 1]
        cols += [shift, shift]
        vals += [et[0], et[1]]
    T = coo_matrix((vals, (rows, cols)), shape=(2 * n, shift + 1)).tocsr()
    return T, u0


def _patch_stress(nodes, tri, sig, at: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Stress ``(k, 3)`` at the nodes ``at`` from a linear least-squares fit of the element stresses whose centroids
    lie within ``radius`` of each (patch recovery)."""
    from scipy.spatial import cKDTree

    cen = nodes[tri].mean(axis=1)
    tree = cKDTree(cen)
    out = np.empty((len(at), 3))
    for j, i in enumerate(at):
        idx = tree.query_ball_point(nodes[i], radius[j])
        if len(idx) < 6:
            idx = tree.query(nodes[i], 6)[1]
        d = cen[idx] - nodes[i]
        M = np.column_stack([np.ones(len(idx)), d])
        coef, *_ = np.linalg.lstsq(M, sig[idx], rcond=None)
        out[j] = coef[0]
    return out


#: the last few results of :func:`root_concentration`, keyed by a digest of everything it reads (a datasheet with a
#: cam offset rates the drive twice, a study's candidates that differ only in the generator share their teeth)
_SOLVED: dict = {}
_SOLVED_MAX = 16


def _geometry_key(gear, bore_radius, pitches, fineness, E, nu) -> bytes:
    """A digest of what the FE model is made of: the tooth's exact pieces (their exact ``repr``) and polyline, the
    counts and sizes the mesh reads, the bore and the settings."""
    import hashlib

    sp = gear.spec
    h = hashlib.sha256()
    h.update(repr(tuple(gear.pieces)).encode())
    h.update(np.asarray(gear.period, dtype=float).tobytes())
    head = [sp.z, sp.module, sp.fillet_coef, gear.r_f, bore_radius, pitches, fineness, E, nu]
    h.update(np.array(head, dtype=float).tobytes())
    return h.digest()


def root_concentration(gear, bore_radius: float, pitches: int = 5, fineness: float = 2.0, E=206e3, nu=0.3):
    """The tooth roots' stress concentration of the flexspline ``gear`` on a rim down to ``bore_radius`` (mm).

    ``pitches`` (odd, >= 3) teeth in the sector, the middle one measured;
    ``fineness`` scales the element size down (default 2: at the roots a twentieth of the fillet radius, elsewhere
    a sixteenth of the rim; tests/test_rating_notch.py). Returns
    :class:`RootConcentration`. ``E`` and ``nu`` only set the plane-strain
    modulus; ``K`` is a ratio and does not depend on them. A geometry solved before in this process (the same
    digest of pieces, outline, sizes and settings) is answered from memory.
    """
    if pitches < 3 or pitches % 2 == 0:
        raise ValueError(f"pitches must be odd and >= 3, got {pitches}")
    key = _geometry_key(gear, bore_radius, pitches, fineness, E, nu)
    got = _SOLVED.get(key)
    if got is None:
        got = _root_concentration(gear, bore_radius, pitches, fineness, E, nu)
        if len(_SOLVED) >= _SOLVED_MAX:
            _SOLVED.pop(next(iter(_SOLVED)))
        _SOLVED[key] = got
    return got


def _root_concentration(gear, bore_radius: float, pitches: int, fineness: float, E, nu) -> RootConcentration:
    from scipy.sparse.linalg import spsolve

    m = gear.spec.module
    r_f = gear.r_f
    h1 = abs(r_f - bore_radius)
    r_m = 0.5 * (r_f + bore_radius)
    rho_f = max(gear.spec.fillet_coef * m, 0.05 * m)
    h_min = rho_f / 10.0 / fineness
    h_max = min(h1 / 8.0, 0.25 * m) / fineness
    outline, corners, half = _sector_boundary(gear, bore_radius, pitches, 0.25 * h_min)
    # the roots of the middle pitch: where the toothed outline is within a fillet radius of the root circle
    pr = np.hypot(gear.period[:, 0], gear.period[:, 1])
    near = np.abs(pr - r_f) < 0.5 * m + rho_f
    size = _GradedSize(gear.period[near], h_min, h_max)
    nodes, tri, n_b = _mesh(outline, size, h_max, corners)
    Ep = E / (1 - nu**2)
    K, B, D, dof, _ = _stiffness(nodes, tri, E, nu)
    dkappa = 1e-4  # 1/mm; linear: any value
    phi_sector = 2 * half
    dalpha = dkappa * r_m * phi_sector
    T, u0 = _end_transform(nodes, half, r_m, dalpha, tol=1e-9 + 1e-6 * h_min / r_f)
    Kr = (T.T @ K @ T).tocsc()
    q = spsolve(Kr, -(T.T @ (K @ u0)))
    u = T @ q + u0
    strain = np.einsum("tij,tj->ti", B, u[dof])
    sig = strain @ D.T
    # boundary nodes of the middle pitch on the toothed side (the first n_b nodes are the outline's)
    bnd = nodes[:n_b]
    ang = np.arctan2(bnd[:, 1], bnd[:, 0])
    rad = np.hypot(bnd[:, 0], bnd[:, 1])
    toothed = np.abs(rad - bore_radius) > 0.25 * h1
    mid = toothed & (np.abs(ang) <= pi / gear.spec.z + 1e-12) & (np.abs(np.abs(ang) - half) > 1e-9)
    at = np.flatnonzero(mid)
    s = _patch_stress(nodes, tri, sig, at, 2.5 * size(bnd[at]))
    prev = np.roll(np.arange(n_b), 1)[at]
    nxt = np.roll(np.arange(n_b), -1)[at]
    t = bnd[nxt] - bnd[prev]
    t /= np.linalg.norm(t, axis=1)[:, None]
    s_tt = s[:, 0] * t[:, 0] ** 2 + s[:, 1] * t[:, 1] ** 2 + 2 * s[:, 2] * t[:, 0] * t[:, 1]
    nominal = Ep * 0.5 * h1 * dkappa
    j = int(np.argmax(s_tt))
    return RootConcentration(
        kt=float(s_tt[j] / nominal),
        angle=float(abs(ang[at[j]])),
        radius=float(rad[at[j]]),
        nodes=len(nodes),
        h_min=float(h_min),
    )
