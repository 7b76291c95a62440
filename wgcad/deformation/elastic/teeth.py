"""Tooth contacts: points, normals and gaps from the exact 2D engine, and the tooth pair's compliance (theory.md 4.1, 5)."""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np
import shapely

from wgcad.clearance.engine import Scene, clearance_at_poses
from wgcad.placement import transform

__all__ = ["ContactGeometry", "flank_contacts", "ToothCompliance"]


@dataclass(frozen=True)
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


def _deepest(poly_pts: np.ndarray, other_geom, other_ring, sign: float):
    """Deepest vertex of ``poly_pts`` inside ``other_geom``: (depth, vertex, nearest boundary point) or None."""
    ins = shapely.contains_xy(other_geom, poly_pts[:, 0], poly_pts[:, 1])
    if not ins.any():
        return None
    cand = poly_pts[ins]
    d = shapely.distance(other_ring, shapely.points(cand))
    i = int(np.argmax(d))
    q = np.asarray(shapely.shortest_line(other_ring, shapely.Point(cand[i])).coords[0])
    return float(d[i]), cand[i], q


def _smooth_normals(outlines: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Outward normals of counter-clockwise outlines ``(K, N, 2)`` at points ``p`` ``(K, 2)`` on them.

    Vertex normals (the mean of the two edge normals) interpolated along the
    nearest edge: a normal field that is continuous along the outline, so the
    contact direction does not jump from edge to edge of the polygon (which
    would leave the re-linearisation cycling by a fraction of a micrometre).
    """
    a = outlines
    b = np.roll(outlines, -1, axis=1)
    ab = b - a
    L2 = np.maximum((ab * ab).sum(axis=-1), 1e-300)
    t = np.clip(((p[:, None, :] - a) * ab).sum(axis=-1) / L2, 0.0, 1.0)
    d2 = ((a + t[..., None] * ab - p[:, None, :]) ** 2).sum(axis=-1)
    e = np.argmin(d2, axis=1)
    en = np.stack([ab[..., 1], -ab[..., 0]], axis=-1) / np.sqrt(L2)[..., None]  # edge i: vertex i -> i+1
    vn = en + np.roll(en, 1, axis=1)  # vertex i: edges i-1 and i
    vn /= np.hypot(vn[..., 0], vn[..., 1])[..., None]
    k = np.arange(len(p))
    N = outlines.shape[1]
    te = t[k, e][:, None]
    n = (1.0 - te) * vn[k, e] + te * vn[k, (e + 1) % N]
    # how sharp the outline turns at the ends of that edge (0: straight, pi/2: a right-angled corner)
    cosang = lambda i: np.clip((en[k, (i - 1) % N] * en[k, i]).sum(axis=-1), -1.0, 1.0)  # noqa: E731
    kink = np.maximum(np.arccos(cosang(e)), np.arccos(cosang((e + 1) % N)))
    return n / np.hypot(n[:, 0], n[:, 1])[:, None], kink


def flank_contacts(scene: Scene, rot: np.ndarray, shift: np.ndarray) -> dict[str, ContactGeometry]:
    """Contacts of flexspline teeth at poses ``(rot, shift)`` with their lower and upper rigid neighbours.

    The gaps are the engine's (:func:`wgcad.clearance.engine.clearance_at_poses`);
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
    res = clearance_at_poses(scene, rot, shift, third=False)
    pts = transform(scene.flex_local, rot, shift)
    geoms = shapely.polygons(pts)
    out = {}
    for key, idx in (("lower", res["lo"]), ("upper", res["up"])):
        gap = np.asarray(res[key], dtype=float)
        rg = scene.rigid_geoms[idx]
        point = np.empty((len(rot), 2))
        other = np.empty((len(rot), 2))
        apart = np.nonzero(gap > 0.0)[0]
        if apart.size:
            seg = shapely.get_coordinates(shapely.shortest_line(geoms[apart], rg[apart])).reshape(-1, 2, 2)
            point[apart] = seg[:, 0]
            other[apart] = seg[:, 1]
        for k in np.nonzero(gap <= 0.0)[0]:
            a_ring = geoms[k].exterior
            b_geom = rg[k]
            flex_in = _deepest(pts[k], b_geom, b_geom.exterior, 1.0)
            rig_pts = scene.rigid_pts[idx[k]]
            rig_in = _deepest(rig_pts, geoms[k], a_ring, -1.0)
            best = None
            if flex_in is not None:
                depth, v, q = flex_in
                best = (depth, v, q)
            if rig_in is not None and (best is None or rig_in[0] > best[0]):
                depth, u, q = rig_in
                best = (depth, q, u)
            if best is None or best[0] <= 0.0:
                # touching without a vertex inside: outward normal of the flexspline outline there
                sl = np.asarray(shapely.shortest_line(a_ring, b_geom.exterior).coords)
                best = (0.0, sl[0], sl[1])
            point[k], other[k] = best[1], best[2]
        # the contact normal is the normal of the smoother outline there: a tip corner pressing on a
        # flank acts along the flank's normal (vertex normals interpolated, so it does not jump)
        n_f, kink_f = _smooth_normals(pts, point)
        n_r, kink_r = _smooth_normals(scene.rigid_pts[idx], other)
        normal = np.where((kink_r < kink_f)[:, None], -n_r, n_f)
        out[key] = ContactGeometry(gap, point, normal, np.asarray(idx))
    return out


@dataclass(frozen=True)
class ToothCompliance:
    """Compliance of one tooth pair along the contact normal over a face-width slice (docs/models.md 4.1).

    Both teeth are cantilevers of thickness ``s`` (the pitch tooth thickness,
    pi m / 2) loaded at their contact heights: bending ``4 h^3 / (E b s^3)``
    plus shear ``1.2 h / (G b s)``, times ``cos^2`` of the angle between the
    normal and the tooth's tangential direction. The flanks' approach is
    Palmgren's steel line contact ``3.84e-5 Q^0.9 / b^0.8`` (mm, N, mm)
    scaled by ``E'_steel / E'``.
    """

    E: float  # MPa
    nu: float
    s: float  # mm, tooth thickness
    r_root_flex: float
    r_root_rigid: float

    def bending(self, point, normal, width):
        """Bending + shear compliance of both teeth, mm/N, for flexspline contact points ``(K, 2)``."""
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

