"""One tooth's exact curves as arrays: points and derivatives of many pieces at once, projection, exact signed distance (docs/models.md 5).

:class:`ExactTooth` holds the analytic pieces of a tooth
(:mod:`wgcad.profiles.pieces`) in the orientation of its polygon, evaluates
points and first and second derivatives of many (piece, parameter) pairs in
one vectorised call, locates polygon vertices on their pieces and projects
points on the curves; :func:`point_signed_distance` is the exact signed
distance of points to the tooth's boundary. The pair refinement
(:mod:`wgcad.clearance.refine`) is built on them.
"""

from __future__ import annotations

import numpy as np
import shapely

__all__ = ["ExactTooth", "point_signed_distance", "curv_h"]

_SEED_GRID = 48  # samples per piece to seed the projection of a point
_GRID_BLOCK = 1 << 20  # squared distances (8 MB) of points to grid points computed in one product


class ExactTooth:
    """One tooth's exact pieces in its own frame, oriented like its (counter-clockwise) polygon.

    Parameters
    ----------
    gear : wgcad.profiles.gear.Gear
    polygon : (N, 2) float
        ``gear.tooth_polygon()``: the period (reversed for internal gears)
        closed through the body by two points.
    """

    def __init__(self, gear, polygon: np.ndarray):
        pcs = list(gear.pieces)
        internal = gear.spec.internal
        if internal:  # the tooth polygon runs the period backwards
            pcs = [p.reversed() for p in reversed(pcs)]
        self.pieces = pcs
        self.n = len(pcs)
        self.lo = np.array([min(p.t0, p.t1) for p in pcs])
        self.hi = np.array([max(p.t0, p.t1) for p in pcs])
        # travel direction of the counter-clockwise polygon along increasing t
        self.sense = np.array([1.0 if p.t1 >= p.t0 else -1.0 for p in pcs])
        # a spline (many cubic segments in one piece) gets four seeds per segment: one seed per 2.6 segments left
        # the projection in a neighbouring segment's basin (a -38 um figure at a contact on D1's conjugate flank)
        self.grid_n = np.array(
            [max(_SEED_GRID, 4 * (len(p.params) // 8) + 1) if p.kind == "spline" else _SEED_GRID for p in pcs]
        )
        grid = [np.linspace(lo, hi, g) for lo, hi, g in zip(self.lo, self.hi, self.grid_n)]
        grid_p = [p.point(g) for p, g in zip(pcs, grid)]
        # grid_t[j, :grid_n[j]]: piece j's seeds (padded with its last one)
        self.grid_t = np.array([np.pad(g, (0, self.grid_n.max() - len(g)), mode="edge") for g in grid])
        # longest step between grid points of each piece: bounds how far the nearest grid point can be
        self.grid_step = np.array([np.hypot(*np.diff(g, axis=0).T).max() for g in grid_p])
        # the pieces of the usual grid are searched by one matrix product; a spline's thousands of seeds by a tree
        self._dense = np.flatnonzero(self.grid_n == _SEED_GRID)
        self._dense_g = _SEED_GRID
        self._dense_p = np.array([grid_p[j] for j in self._dense]).reshape(-1, 2)
        self._trees = [
            (j, shapely.STRtree(shapely.points(grid_p[j]))) for j in np.flatnonzero(self.grid_n != _SEED_GRID)
        ]
        # every vertex of the period part of the polygon: its piece and parameter. The polygon of an internal
        # gear's tooth runs the two body points first, then the period backwards (Gear.tooth_polygon)
        n_per = len(gear.period)
        first = len(polygon) - n_per if internal else 0
        self.vert_index = np.arange(first, first + n_per)
        verts = polygon[self.vert_index]
        self.vert_piece, self.vert_t = self._locate(verts)
        self.n_vert = n_per
        # farther than the chord tolerance from the curves, the polygon tells inside from outside
        # exactly; it also closes the tooth through the body where no piece runs
        self.polygon = shapely.Polygon(polygon)
        shapely.prepare(self.polygon)
        self.tol = float(gear.tol)

    def nearest_grid(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Squared distance ``(K, n)`` of each of the points ``(K, 2)`` to the nearest grid point of every piece, and
        that grid point's index (``grid_t[j, index]`` its parameter).

        The usual grids in one matrix product, as ``|p|^2 + |g|^2 - 2 p.g``
        about their centre (no (K, n, G, 2) temporary); a spline's fine grid
        (four seeds a segment) by a nearest-neighbour query of its own tree
        (every piece seeded at a spline's count, one (K, n, G) array, was the
        largest cost of a conjugate gear's audit). The distances pick seeds
        and candidate pieces, so the rounding (~1e-13 mm^2) does not matter.
        """
        K = len(pts)
        d2 = np.full((K, self.n), np.nan)  # a point the tree cannot place (not finite) stays nan, as in the product
        arg = np.zeros((K, self.n), dtype=np.intp)
        if self._dense.size:
            if not hasattr(self, "_g_c"):
                self._g_c = self._dense_p.mean(axis=0)
                self._g_rel = self._dense_p - self._g_c
                self._g_n2 = (self._g_rel**2).sum(-1)
            # in blocks of points, so the (points, grid) product stays near 8 MB however many points come at once
            # (one block of a cycloidal tooth's refinement was 45 MB, the largest array of its audit)
            step = max(1, _GRID_BLOCK // len(self._g_n2))
            for a in range(0, K, step):
                p = pts[a : a + step] - self._g_c
                dd = (p**2).sum(-1)[:, None] + self._g_n2[None, :] - 2.0 * (p @ self._g_rel.T)
                dd = np.maximum(dd, 0.0).reshape(len(p), len(self._dense), self._dense_g)
                g = dd.argmin(axis=2)
                arg[a : a + step, self._dense] = g
                d2[a : a + step, self._dense] = np.take_along_axis(dd, g[:, :, None], axis=2)[:, :, 0]
        if self._trees:
            geoms = shapely.points(pts)
            for j, tree in self._trees:
                (i, g), dist = tree.query_nearest(geoms, return_distance=True, all_matches=False)
                d2[i, j], arg[i, j] = dist * dist, g
        return d2, arg

    def _tables(self):
        """Per-piece parameters as arrays, so one call evaluates many pieces of one kind (by kind, not by piece)."""
        n = self.n
        self.kind = np.array(
            [
                {"arc": 0, "line": 1, "involute": 2, "epicycloid": 3, "hypocycloid": 3, "cubic": 4, "spline": 5}[p.kind]
                for p in self.pieces
            ]
        )
        par = np.zeros((n, 8))
        for i, p in enumerate(self.pieces):
            if p.kind == "arc":
                par[i, :3] = p.params
            elif p.kind == "line":
                par[i, :4] = p.params
            elif p.kind == "cubic":
                par[i] = p.params
            elif p.kind == "spline":
                pass  # its segments: rows of the segment table below
            elif p.kind == "involute":
                par[i, :2] = p.params
            else:
                par[i, :3] = (p.params[0], p.params[1], 1.0 if p.kind == "epicycloid" else -1.0)
        self.par = par
        # every spline's Bezier segments in one table: piece i's segment k is row seg0[i] + k (of nseg[i])
        segs = [
            np.asarray(p.params, dtype=float).reshape(-1, 8) if p.kind == "spline" else np.zeros((0, 8))
            for p in self.pieces
        ]
        self.nseg = np.array([len(a) for a in segs])
        self.seg0 = np.concatenate([[0], np.cumsum(self.nseg)[:-1]])
        self.seg_par = np.ascontiguousarray(np.concatenate(segs).T)  # (8, segments)
        self.rot = np.array([p.rot for p in self.pieces])
        self.flip = np.array([p.flip for p in self.pieces])
        self.cos_rot, self.sin_rot = np.cos(self.rot), np.sin(self.rot)
        self.kinds = np.unique(self.kind)

    def eval(self, idx: np.ndarray, t: np.ndarray, order: int = 2):
        """Point, first and second derivative ``(K, 2)`` each, for pieces ``idx`` at parameters ``t``."""
        if not hasattr(self, "par"):
            self._tables()
        K = len(t)
        P = np.empty((K, 2))
        D1 = np.empty((K, 2))
        D2 = np.empty((K, 2))
        kind = self.kind[idx]
        for kd in self.kinds:
            sel = kind == kd
            if not sel.any():
                continue
            ii, tt = idx[sel], t[sel]
            if kd != 5:
                pr = self.par[ii]
            if kd == 0:  # arc
                c, s_ = np.cos(tt), np.sin(tt)
                R = pr[:, 2]
                P[sel, 0], P[sel, 1] = pr[:, 0] + R * c, pr[:, 1] + R * s_
                D1[sel, 0], D1[sel, 1] = -R * s_, R * c
                D2[sel, 0], D2[sel, 1] = -R * c, -R * s_
                continue
            if kd == 1:  # line
                P[sel, 0], P[sel, 1] = pr[:, 0] + tt * pr[:, 2], pr[:, 1] + tt * pr[:, 3]
                D1[sel, 0], D1[sel, 1] = pr[:, 2], pr[:, 3]
                D2[sel] = 0.0
                continue
            if kd == 2:  # involute, polar form (docs/models.md 2.1)
                psi, rb = pr[:, 0], pr[:, 1]
                s2 = 1.0 + tt * tt
                sq = np.sqrt(s2)
                a = psi - (tt - np.arctan(tt))
                ca, sa = np.cos(a), np.sin(a)
                rad, rad1, rad2 = rb * sq, rb * tt / sq, rb / (s2 * sq)
                a1, a2 = -tt * tt / s2, -2.0 * tt / (s2 * s2)
                cu = rad
                du, dn = rad1, rad * a1
                eu, en = rad2 - rad * a1 * a1, 2.0 * rad1 * a1 + rad * a2
                px, py = cu * ca, cu * sa
                qx, qy = du * ca - dn * sa, du * sa + dn * ca
                rx, ry = eu * ca - en * sa, eu * sa + en * ca
            elif kd == 5:  # spline: segment floor(t), a cubic Bezier in t - floor(t) (pieces._eval, term by term)
                seg = np.floor(tt).astype(np.intp)
                np.clip(seg, 0, self.nseg[ii] - 1, out=seg)
                x0, y0, x1, y1, x2, y2, x3, y3 = self.seg_par[:, self.seg0[ii] + seg]  # (8, K): one row a number
                v = tt - seg
                u = 1.0 - v
                b0, b1, b2, b3 = u**3, 3 * u * u * v, 3 * u * v * v, v**3
                px, py = b0 * x0 + b1 * x1 + b2 * x2 + b3 * x3, b0 * y0 + b1 * y1 + b2 * y2 + b3 * y3
                b0, b1, b2 = 3 * u * u, 6 * u * v, 3 * v * v
                qx = b0 * (x1 - x0) + b1 * (x2 - x1) + b2 * (x3 - x2)
                qy = b0 * (y1 - y0) + b1 * (y2 - y1) + b2 * (y3 - y2)
                b0, b1 = 6 * u, 6 * v
                rx, ry = (
                    b0 * (x2 - 2 * x1 + x0) + b1 * (x3 - 2 * x2 + x1),
                    b0 * (y2 - 2 * y1 + y0) + b1 * (y3 - 2 * y2 + y1),
                )
            elif kd == 4:  # cubic Bezier (pieces._cubic)
                P0, P1, P2, P3 = pr[:, 0:2], pr[:, 2:4], pr[:, 4:6], pr[:, 6:8]
                u = (1.0 - tt)[:, None]
                v = tt[:, None]
                b = u**3 * P0 + 3 * u * u * v * P1 + 3 * u * v * v * P2 + v**3 * P3
                d = 3 * u * u * (P1 - P0) + 6 * u * v * (P2 - P1) + 3 * v * v * (P3 - P2)
                e = 6 * u * (P2 - 2 * P1 + P0) + 6 * v * (P3 - 2 * P2 + P1)
                px, py, qx, qy, rx, ry = b[:, 0], b[:, 1], d[:, 0], d[:, 1], e[:, 0], e[:, 1]
            else:  # epi/hypocycloid in u = 1 - cos(phi/2) (pieces._cycloid)
                r, rho, sg = pr[:, 0], pr[:, 1], pr[:, 2]
                k = rho / r
                A = r + sg * rho
                uu = np.clip(tt, 0.0, 2.0)
                phi = 4.0 * np.arcsin(np.sqrt(0.5 * uu))
                b1, b2 = k * phi, (k + sg) * phi
                px = A * np.cos(b1) - sg * rho * np.cos(b2)
                py = A * np.sin(b1) - sg * rho * np.sin(b2)
                m = 0.5 * (2.0 * k + sg) * phi
                cm, sm = np.cos(m), np.sin(m)
                sp = 4.0 * A * k * sg
                qx, qy = sp * cm, sp * sm
                mu = (2.0 * k + sg) / np.maximum(np.sin(0.5 * phi), 1e-12)
                rx, ry = -sp * mu * sm, sp * mu * cm
            fl = self.flip[ii]
            c, s_ = self.cos_rot[ii], self.sin_rot[ii]
            for out, x, y in ((P, px, py), (D1, qx, qy), (D2, rx, ry)):
                y = fl * y
                out[sel, 0], out[sel, 1] = c * x - s_ * y, s_ * x + c * y
        return P, D1, D2

    def outward(self, idx: np.ndarray, d1: np.ndarray) -> np.ndarray:
        """Unit normals ``(K, 2)`` pointing out of the material (right of the counter-clockwise travel)."""
        s = self.sense[idx][:, None]
        n = s * np.stack([d1[:, 1], -d1[:, 0]], axis=-1)
        return n / np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-300)[:, None]

    def _locate(self, pts: np.ndarray):
        """Piece index and parameter of points that lie on the pieces (the polygon's vertices)."""
        d2, arg = self.nearest_grid(pts)  # (V, n)
        idx = d2.argmin(axis=1)
        t = self.grid_t[idx, arg[np.arange(len(pts)), idx]]
        t = self._project(pts, idx, t)
        return idx, t

    def _project(self, pts, idx, t, steps: int = 40):
        """Newton on ``(P(t) - x) . P'(t) = 0`` within each piece's range."""
        lo, hi = self.lo[idx], self.hi[idx]
        t = np.array(t, dtype=float)
        live = np.arange(len(t))  # a row stops once its step is below 1e-15 relative; the others go on
        for _ in range(steps):
            P, d1, d2 = self.eval(idx[live], t[live])
            r = P - pts[live]
            g = (r * d1).sum(-1)
            t_new = np.clip(t[live] - g / curv_h(d1, r, d2), lo[live], hi[live])
            done = np.abs(t_new - t[live]) <= 1e-15 * np.maximum(1.0, np.abs(t[live]))
            t[live] = t_new
            live = live[~done]
            if live.size == 0:
                break
        return t


def point_signed_distance(tooth: ExactTooth, pts: np.ndarray) -> np.ndarray:
    """Exact signed distance ``(K,)`` of points ``(K, 2)`` (tooth frame) to the tooth's boundary: > 0 outside its material.

    Each point is projected on every piece (grid seed, clamped Newton); the
    nearest projection gives the distance, the outward normal there the sign
    (at a corner shared by two pieces, the piece whose normal is more nearly
    along the offset decides).
    """
    K = len(pts)
    n = tooth.n
    d2, g = tooth.nearest_grid(pts)  # (K, n) each
    gmin = np.sqrt(d2)  # (K, n): nearest grid point of each piece
    # a piece can hold the nearest point only if its nearest grid point is within one grid step of the best
    cand = gmin <= gmin.min(axis=1, keepdims=True) + tooth.grid_step[None, :]
    kk, idx = np.nonzero(cand)
    t0 = tooth.grid_t[idx, g[kk, idx]]
    rep = pts[kk]
    t = tooth._project(rep, idx, t0)
    P, d1, _ = tooth.eval(idx, t, order=1)
    D = rep - P
    dist = np.full((K, n), np.inf)
    dist[kk, idx] = np.hypot(D[:, 0], D[:, 1])
    nrm = tooth.outward(idx, d1)
    cos = np.zeros((K, n))
    cos[kk, idx] = (D * nrm).sum(-1) / np.maximum(np.hypot(D[:, 0], D[:, 1]), 1e-300)
    best = dist.min(axis=1)
    # among pieces whose distance ties the nearest (a corner), trust the most normal offset
    tie = dist <= best[:, None] + 1e-12
    c = np.where(tie, cos, 0.0)
    j = np.abs(c).argmax(axis=1)
    sign = np.sign(c[np.arange(K), j])
    sign[sign == 0] = 1.0
    # away from the curves (or off the ends of the period, where the nearest curve point is an end
    # and the offset runs along the curve) the polygon decides
    far = best > 1.5 * tooth.tol
    if far.any():
        ins = shapely.contains_xy(tooth.polygon, pts[far, 0], pts[far, 1])
        sign[far] = np.where(ins, -1.0, 1.0)
    return sign * best


def curv_h(d1, r, d2):
    """Second derivative of ``|P(t) - x|^2 / 2`` (``r = P - x``), kept within [0.1, 100] times the Gauss-Newton term.

    Newton's curvature term ``r . P''`` is unbounded at the pitch-point cusp of
    cycloidal flanks (``P''`` ~ ``1/sqrt(u)``) and negative beyond a centre of
    curvature; the clamp keeps every step a descent step of bounded length.
    """
    gn = np.maximum((d1 * d1).sum(-1), 1e-300)
    return np.clip(gn + (r * d2).sum(-1), 0.1 * gn, 100.0 * gn)
