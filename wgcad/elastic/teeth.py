"""Tooth contacts: points, normals and gaps from the exact 2D engine, and the tooth pair's compliance (docs/models.md 4.1, 5)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from wgcad.clearance.engine import Scene
from wgcad.placement import transform
from wgcad.plane import rotate

__all__ = ["ContactGeometry", "flank_contacts", "pair_contacts", "ToothCompliance"]


@dataclass(frozen=True, slots=True)
class ContactGeometry:
    """Linearised contacts between placed flexspline teeth and rigid teeth (rigid-gear frame), arrays of length K.

    Attributes
    ----------
    gap : (K,) float
        Signed clearance from the engine, mm (negative: penetration depth).
    point : (K, 2) float
        The point of the flexspline tooth where the gap is measured.
    normal : (K, 2) float
        Outward unit normal of the flexspline outline at ``point``: a motion of
        the flexspline point along it closes the gap (``d gap = -normal . d point``).
    rigid : (K,) int
        Index of the rigid tooth.
    """

    gap: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    rigid: np.ndarray


def _deepest(pts: np.ndarray, template, rot: np.ndarray, shift: np.ndarray):
    """Deepest vertex of each polygon ``pts[k]`` ``(K, N, 2)`` inside the copy ``R(rot[k]) template + shift[k]``.

    Worked in the template's frame against its one prepared polygon (as the
    engine's ``Template.depth_of``). Returns depth ``(K,)`` (0 where no
    vertex is inside), the vertex ``(K, 2)`` and its nearest point on the
    copy's boundary ``(K, 2)``, both in the frame of ``pts``.
    """
    K, N, _ = pts.shape
    depth = np.zeros(K)
    vert = pts[:, 0].copy()
    near = pts[:, 0].copy()
    c, s = np.cos(rot)[:, None], np.sin(rot)[:, None]
    d = pts - shift[:, None, :]
    qx, qy = c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]
    ins = shapely.contains_xy(template.polygon, qx, qy)
    kk, ii = np.nonzero(ins)
    if kk.size == 0:
        return depth, vert, near
    # distance of the inside vertices to the outline and the nearest point on it, every edge at once (the
    # engine's Template.boundary_distance, which also keeps the point)
    loc = template.local
    ab, L2, _, _ = _outline(loc)
    q = np.stack([qx[kk, ii], qy[kk, ii]], axis=-1)
    e, t = _project(loc, ab, L2, q)
    foot = loc[e] + t[:, None] * ab[e]
    dist = np.hypot(*(q - foot).T)
    full = np.full((K, N), -1.0)
    full[kk, ii] = dist
    best = np.argmax(full, axis=1)
    has = full[np.arange(K), best] > 0.0
    k = np.nonzero(has)[0]
    depth[k] = full[k, best[k]]
    vert[k] = pts[k, best[k]]
    fk = np.full((K, N), -1, dtype=int)
    fk[kk, ii] = np.arange(len(kk))
    nl = foot[fk[k, best[k]]]
    ck, sk = c[k, 0], s[k, 0]
    near[k] = np.stack([ck * nl[:, 0] - sk * nl[:, 1], sk * nl[:, 0] + ck * nl[:, 1]], axis=-1) + shift[k]
    return depth, vert, near


def _project(a: np.ndarray, ab: np.ndarray, L2: np.ndarray, q: np.ndarray):
    """Nearest edge ``e`` ``(K,)`` of a closed outline (vertices ``a`` ``(N, 2)``, edges ``ab`` from vertex i to i+1,
    squared lengths ``L2``) to points ``q`` ``(K, 2)``, and the place ``t`` in [0, 1] on it of the nearest point.

    What ``shapely.line_locate_point`` on the outline's ring gives, without building a geometry per call (the
    first edge where two are equally near: at a shared vertex both give the same interpolated normal).
    """
    rel = q[:, None, :] - a[None, :, :]  # (K, N, 2)
    t = np.clip((rel[..., 0] * ab[:, 0] + rel[..., 1] * ab[:, 1]) / L2, 0.0, 1.0)
    dx, dy = rel[..., 0] - t * ab[:, 0], rel[..., 1] - t * ab[:, 1]
    e = np.argmin(dx * dx + dy * dy, axis=1)
    return e, t[np.arange(len(q)), e]


_OUTLINES: dict = {}


def _outline(local: np.ndarray):
    """Edges ``ab`` ``(N, 2)`` (vertex i to i+1), their squared lengths, the unit vertex normals (mean of the two
    edge normals) and how sharp the outline turns at the ends of each edge, rad: computed once per outline."""
    key = local.tobytes()
    got = _OUTLINES.get(key)
    if got is None:
        ab = np.roll(local, -1, axis=0) - local
        L2 = np.maximum((ab * ab).sum(axis=-1), 1e-300)
        en = np.stack([ab[:, 1], -ab[:, 0]], axis=-1) / np.sqrt(L2)[:, None]  # edge i: vertex i -> i+1
        vn = en + np.roll(en, 1, axis=0)  # vertex i: edges i-1 and i
        vn /= np.hypot(vn[:, 0], vn[:, 1])[:, None]
        turn = np.arccos(np.clip((np.roll(en, 1, axis=0) * en).sum(axis=-1), -1.0, 1.0))  # at vertex i
        got = (ab, L2, vn, np.maximum(turn, np.roll(turn, -1)))
        for x in got:
            x.setflags(write=False)
        if len(_OUTLINES) > 32:
            _OUTLINES.clear()
        _OUTLINES[key] = got
    return got


def _smooth_normals(local: np.ndarray, rot: np.ndarray, shift: np.ndarray, p: np.ndarray):
    """Outward normals of copies ``R(rot) local + shift`` of one counter-clockwise outline at points ``p`` ``(K, 2)`` on them.

    Vertex normals (the mean of the two edge normals) interpolated along the
    nearest edge: a normal field that is continuous along the outline, so the
    contact direction does not jump from edge to edge of the polygon (which
    would leave the re-linearisation cycling by a fraction of a micrometre).
    Worked in the outline's own frame (one template for every copy).

    Returns
    -------
    normal : (K, 2) float
    kink : (K,) float
        How sharp the outline turns at the ends of that edge, rad (0: straight, pi/2: a right-angled corner).
    """
    ab, L2, vn, kink_edge = _outline(local)
    # the points in the template's frame
    c, s = np.cos(rot), np.sin(rot)
    d = p - shift
    q = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=-1)
    # the nearest edge and the place on it (the points lie on the outline): every edge at once, (K, N)
    e, te = _project(local, ab, L2, q)
    N = len(local)
    te = te[:, None]
    n = (1.0 - te) * vn[e] + te * vn[(e + 1) % N]
    n /= np.hypot(n[:, 0], n[:, 1])[:, None]
    return rotate(n, rot), kink_edge[e]


def flank_contacts(scene: Scene, rot: np.ndarray, shift: np.ndarray) -> dict[str, ContactGeometry]:
    """Contacts of flexspline teeth at poses ``(rot, shift)`` with their lower and upper rigid neighbours.

    The gaps are the engine's (:func:`wgcad.clearance.engine.clearance_at_poses`, the same
    definition computed here from the shortest segments and deepest vertices it also needs);
    the point and normal come from the shortest segment between the outlines
    when apart, and from the deepest vertex and its nearest point on the other
    outline when overlapping (the vertex that sets the engine's depth): the
    point where the gap is measured, and ``-normal`` approximates the gradient
    of the gap with respect to a translation of
    the flexspline tooth in both cases. The normal is the outward normal of
    the flexspline outline at that point, or the inward normal of the rigid
    outline at its point when that outline is the smoother one there (a
    corner against a flank), interpolated between vertex normals.

    Returns
    -------
    dict with keys ``"lower"``, ``"upper"`` of :class:`ContactGeometry`.
    """
    rot = np.atleast_1d(np.asarray(rot, dtype=float))
    shift = np.atleast_2d(np.asarray(shift, dtype=float))
    K = len(rot)
    lo, up, _ = scene.neighbours(shift, rot)
    # both neighbours in one batch: pairs 0..K-1 with the lower rigid tooth, K..2K-1 with the upper
    g = pair_contacts(scene, np.concatenate([rot, rot]), np.concatenate([shift, shift]), np.concatenate([lo, up]))
    return {
        key: ContactGeometry(g.gap[sl], g.point[sl], g.normal[sl], g.rigid[sl])
        for key, sl in (("lower", slice(0, K)), ("upper", slice(K, 2 * K)))
    }


def pair_contacts(scene: Scene, rot: np.ndarray, shift: np.ndarray, rigid: np.ndarray) -> ContactGeometry:
    """:func:`flank_contacts` of flexspline teeth at poses ``(rot, shift)`` against given rigid teeth ``rigid`` ``(K,)``."""
    idx = np.asarray(rigid)
    pts = transform(scene.flex_local, rot, shift)
    geoms = shapely.polygons(pts)
    rg = scene.rigid_geoms[idx]
    # the engine's signed clearance (wgcad.clearance.distance.signed_clearance): the distance when apart,
    # minus the depth of the deepest vertex of either polygon inside the other when overlapping
    seg = shapely.get_coordinates(shapely.shortest_line(geoms, rg)).reshape(-1, 2, 2)
    point, other = seg[:, 0].copy(), seg[:, 1].copy()
    gap = np.hypot(*(other - point).T)
    over = np.nonzero(gap == 0.0)[0]
    if over.size:
        # the vertex that sets the engine's depth: of the flexspline inside the rigid tooth, or the reverse
        d_f, v_f, q_f = _deepest(pts[over], scene.rigid, scene.rigid_rot[idx[over]], scene.rigid_shift[idx[over]])
        d_r, v_r, q_r = _deepest(scene.rigid_pts[idx[over]], scene.flex, rot[over], shift[over])
        gap[over] = -np.maximum(d_f, d_r)
        flex_side = d_f >= d_r
        point[over] = np.where(flex_side[:, None], v_f, q_r)
        other[over] = np.where(flex_side[:, None], q_f, v_r)
        touch = np.nonzero(np.maximum(d_f, d_r) <= 0.0)[0]
        if touch.size:  # touching without a vertex inside
            k = over[touch]
            seg = shapely.get_coordinates(
                shapely.shortest_line(shapely.get_exterior_ring(geoms[k]), shapely.get_exterior_ring(rg[k]))
            ).reshape(-1, 2, 2)
            point[k], other[k] = seg[:, 0], seg[:, 1]
    # the contact normal is the normal of the smoother outline there: a tip corner pressing on a
    # flank acts along the flank's normal (vertex normals interpolated, so it does not jump)
    n_f, kink_f = _smooth_normals(scene.flex_local, rot, shift, point)
    n_r, kink_r = _smooth_normals(scene.rigid.local, scene.rigid_rot[idx], scene.rigid_shift[idx], other)
    normal = np.where((kink_r < kink_f)[:, None], -n_r, n_f)
    return ContactGeometry(gap, point, normal, idx)


@dataclass(frozen=True, slots=True)
class ToothCompliance:
    """Compliance of one tooth pair along the contact normal over a face-width slice (docs/models.md 4.1).

    Both teeth are cantilevers of thickness ``s`` (the pitch tooth thickness,
    pi m / 2) loaded at their contact heights: bending ``4 h^3 / (E b s^3)``
    plus shear ``1.2 h / (G b s)``, times ``cos^2`` of the angle between the
    normal and the tooth's tangential direction. The flanks' approach is
    Palmgren's steel line contact ``3.84e-5 Q^0.9 / b^0.8`` (mm, N, mm)
    scaled by ``E'_steel / E'``. ``with_bending`` False leaves the flanks' approach alone, as [S1] writes the
    pair's ``lambda(Q)`` (``[load] tooth_compliance = "hertz"``).
    """

    E: float  # MPa
    nu: float
    s: float  # mm, tooth thickness
    r_root_flex: float
    r_root_rigid: float
    with_bending: bool = True

    def bending(self, point, normal, width):
        """Bending + shear compliance of both teeth, mm/N, for flexspline contact points ``(K, 2)``."""
        if not self.with_bending:
            return np.zeros(len(point))
        R = np.hypot(point[:, 0], point[:, 1])
        er = point / R[:, None]
        c_t = np.abs(normal[:, 0] * -er[:, 1] + normal[:, 1] * er[:, 0])  # |n . e_t|
        G = self.E / (2.0 * (1.0 + self.nu))
        out = np.zeros(len(R))
        for h in (np.abs(R - self.r_root_flex), np.abs(self.r_root_rigid - R)):
            h = np.maximum(h, 0.05 * self.s)
            out += 4.0 * h**3 / (self.E * width * self.s**3) + 1.2 * h / (G * width * self.s)
        return out * c_t**2

    def hertz(self, Q, width):
        """Palmgren line-contact approach of the flanks, mm, for normal loads ``Q`` (N)."""
        scale = (2.06e5 / (1 - 0.3**2)) / (self.E / (1 - self.nu**2))
        return scale * 3.84e-5 * np.maximum(Q, 0.0) ** 0.9 / np.asarray(width) ** 0.8

    def tangent(self, Q, width, q_floor: float):
        """Newton linearisation of :meth:`hertz` about ``Q``: ``(offset, slope)``, secant at ``q_floor`` for ``Q <= q_floor``."""
        Q = np.asarray(Q, dtype=float)
        on = Q > q_floor
        Qf = np.where(on, Q, q_floor)
        lam = self.hertz(Qf, width)
        return np.where(on, 0.1 * lam, 0.0), np.where(on, 0.9 * lam / Qf, lam / Qf)

    def secant(self, Q, width, q_floor: float):
        """Secant compliance ``hertz(Q)/Q`` with ``Q`` floored at ``q_floor`` N, mm/N."""
        Q = np.maximum(np.asarray(Q, dtype=float), q_floor)
        return self.hertz(Q, width) / Q
