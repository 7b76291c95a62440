"""A drive's static data for clearance queries, and the signed clearance of placed teeth on polygons and exact curves (docs/models.md 5)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from math import pi

import numpy as np
import shapely

from ..kinematics import gear_ratios
from ..placement import pose_from_displacements, tooth_frames, tooth_pose, transform
from .distance import Template, signed_clearance
from .refine import ExactTooth, apart_pairs, refine_pairs

__all__ = [
    "Scene",
    "PairFigures",
    "tooth_clearance",
    "tooth_clearance_sections",
    "clearance_at_poses",
    "refine_min",
    "classify",
]

# the pairs a placed tooth is measured against, in the order of PairFigures.pairs
_SIDES = ("lower", "upper", "third")


@dataclass(frozen=True, slots=True)
class PairFigures:
    """Signed clearance of K placed flexspline teeth to the rigid teeth below, above and third nearest.

    Attributes
    ----------
    lower, upper, third : (K,) float
        Clearance to each pair's rigid tooth, mm (negative: penetration
        depth; inf: not measured).
    min : (K,) float
        Each tooth's smallest of the three.
    lo, up, th : (K,) int
        The rigid teeth below, above and third nearest.
    lower_area, upper_area : (K,) float or None
        Overlap areas of the lower and upper pairs, mm^2 (measured on request).
    """

    lower: np.ndarray
    upper: np.ndarray
    third: np.ndarray
    min: np.ndarray
    lo: np.ndarray
    up: np.ndarray
    th: np.ndarray
    lower_area: np.ndarray | None = None
    upper_area: np.ndarray | None = None

    @classmethod
    def full(cls, n: int) -> PairFigures:
        """``n`` teeth not measured yet: every figure inf, every rigid index 0 (a store filled by :meth:`put`)."""
        inf = [np.full(n, np.inf) for _ in range(4)]
        return cls(*inf, *(np.zeros(n, dtype=int) for _ in range(3)))

    def take(self, idx) -> PairFigures:
        """The figures of teeth ``idx`` (an index array or a mask)."""
        area = [None if a is None else a[idx] for a in (self.lower_area, self.upper_area)]
        return PairFigures(*(a[idx] for a in self._measured()), *area)

    def put(self, idx, other: PairFigures) -> None:
        """Write ``other``'s figures and rigid indices into teeth ``idx`` of this store (its areas are not kept)."""
        for mine, theirs in zip(self._measured(), other._measured()):
            mine[idx] = theirs

    def pairs(self) -> np.ndarray:
        """``(K, 3)``: each tooth's lower, upper and third figures."""
        return np.stack([self.lower, self.upper, self.third], axis=1)

    def nearest(self, i: int) -> tuple[str, int]:
        """The pair holding tooth ``i``'s smallest figure (lower, upper, third: the first on a tie) and its rigid tooth."""
        side = min(_SIDES, key=lambda s: getattr(self, s)[i])
        rigid = {"lower": self.lo, "upper": self.up, "third": self.th}[side]
        return side, int(rigid[i])

    def overlap_area(self, side: str, i: int) -> float:
        """Tooth ``i``'s overlap area with the rigid tooth of pair ``side``, mm^2 (0 for the third or unmeasured)."""
        area = {"lower": self.lower_area, "upper": self.upper_area}.get(side)
        return 0.0 if area is None else float(area[i])

    def _measured(self):
        return self.lower, self.upper, self.third, self.min, self.lo, self.up, self.th


class Scene:
    """Static data of a drive for clearance queries: tooth templates and rigid teeth (rigid-gear frame)."""

    def __init__(self, drive):
        self.drive = drive
        d = drive.design.drive
        self.z_g, self.z_b, self.n_w = d.z_flex, d.z_rigid, d.waves
        self.gamma_b = 2.0 * pi / self.z_b
        self.flex = Template(drive.flex.tooth_polygon())
        self.flex_local = self.flex.local
        # the vertices that can be a tooth's outermost (innermost, external deformation)
        # point: enough for the radial bound, which is then exact for the polygon
        R_loc = np.hypot(self.flex_local[:, 0], self.flex_local[:, 1])
        g = drive.flex
        near_tip = np.abs(R_loc - g.r_a) <= 0.5 * abs(g.r_a - g.r_f)
        self.flex_tip_local = np.ascontiguousarray(self.flex_local[near_tip])
        self.rigid = Template(drive.rigid.tooth_polygon())
        self.rigid_rot = (np.arange(self.z_b) + 0.5) * self.gamma_b  # tooth centres: the space is on +x
        self.rigid_shift = np.zeros((self.z_b, 2))
        self.rigid_pts = transform(self.rigid.local, self.rigid_rot, self.rigid_shift)
        self.rigid_pts.setflags(write=False)
        self.rigid_geoms = shapely.polygons(self.rigid_pts)
        shapely.prepare(self.rigid_geoms)
        self.external = drive.external
        self.r_tip_b = drive.rigid.r_a
        # smallest radius of a rigid tooth polygon (its tip inward, or its body closure for external teeth)
        self.rigid_r_min = float(np.hypot(self.rigid.local[:, 0], self.rigid.local[:, 1]).min())
        self.ratios = gear_ratios(self.z_g, self.z_b)
        rot = 1.0 if d.rotation == "ccw" else -1.0
        # Relative motion of the flexspline against the rigid gear has the sign of
        # rot / u_hg. The rigid teeth drive the flexspline (or are driven by it)
        # through the flank that faces against that motion: the working flank.
        rel = rot / self.ratios["u_hg"]
        self.working = "upper" if rel < 0 else "lower"
        # how far a polygon figure can be from the curves' one: every vertex is on its curve and every chord
        # within tol of it, so a distance, and a depth measured from vertices, moves by at most tol per tooth
        # (docs/models.md 5)
        self.chord_gap = 2.0 * drive.tol
        tip = [
            p
            for p in drive.flex.pieces
            if p.kind == "arc"
            and np.allclose(p.center, 0.0, atol=1e-12)
            and abs(p.radius - drive.flex.r_a) <= 1e-9 * drive.flex.r_a
        ]
        self.tip_arc = tip[0] if tip else None
        self.entry_sign = rot  # teeth enter engagement on the side the generator turns toward
        self._laws = {}

    @cached_property
    def flex_exact(self) -> ExactTooth:
        """The flexspline tooth's exact pieces, built on first use (a scene of finer polygons measures none)."""
        return ExactTooth(self.drive.flex, self.flex.local)

    @cached_property
    def rigid_exact(self) -> ExactTooth:
        """The rigid tooth's exact pieces, built on first use."""
        return ExactTooth(self.drive.rigid, self.rigid.local)

    def law(self, z):
        if z is None:
            return self.drive.law
        if z not in self._laws:
            self._laws[z] = self.drive.law_at(z)
        return self._laws[z]

    def pose(self, phi: np.ndarray, z=None):
        """Pose (rotation, shift) of a tooth at angle ``phi`` from the major axis, rigid frame.

        The generator angle is the one that brings a tooth to ``phi`` with its
        material angle at ``phi (z_b - z_g)/z_b``: by the mesh period every
        tooth at ``phi`` is congruent to this one relative to the rigid teeth.
        """
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        mat = phi * (self.z_b - self.z_g) / self.z_b
        return tooth_pose(self.law(z), phi, self.drive.r_m, frame_angle=mat - phi)

    def pose_sections(self, phi: np.ndarray, zi: np.ndarray, zs: list):
        """Poses of teeth at angles ``phi[k]`` in sections ``zs[zi[k]]``, in one go.

        For laws linear in W0 (all but the exact ellipse) a coned section's
        displacements are the centre section's scaled by ``W0(z)/W0``: one
        evaluation of the law serves every section.
        """
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        zi = np.asarray(zi)
        mat = phi * (self.z_b - self.z_g) / self.z_b
        base = self.drive.law
        if base.linear_in_w0:
            st = base.state(phi)
            f = np.array([self.law(z).w0 / base.w0 for z in zs])[zi]
            off = np.array([self.law(z).tooth_offset for z in zs])[zi]
            return pose_from_displacements(phi, f * st.w, f * st.v, f * st.theta, self.drive.r_m, mat - phi, off)
        rot = np.empty(len(phi))
        shift = np.empty((len(phi), 2))
        for i, z in enumerate(zs):
            sel = zi == i
            if sel.any():
                rot[sel], shift[sel] = self.pose(phi[sel], z)
        return rot, shift

    def place(self, phi: np.ndarray, z=None, local=None) -> np.ndarray:
        """Tooth polygons at tooth angles ``phi``, rigid frame, ``(K, N, 2)``."""
        return transform(self.flex_local if local is None else local, *self.pose(phi, z))

    def neighbours(self, shift: np.ndarray, rot: np.ndarray):
        """Indices of the rigid teeth below and above each placed tooth (by the angle of its centre line), and the third nearest."""
        c = self.drive.r_m  # a point on the tooth's centre line
        x = shift[:, 0] + c * np.cos(rot)
        y = shift[:, 1] + c * np.sin(rot)
        a = np.arctan2(y, x)
        f = a / self.gamma_b - 0.5
        lo = np.floor(f).astype(int)
        third = np.where(f - lo < 0.5, lo - 1, lo + 2)
        return lo % self.z_b, (lo + 1) % self.z_b, third % self.z_b

    def speed_bound(self, phi: np.ndarray, z=None) -> float:
        """Largest speed (mm per rad of ``phi``) of any tooth point relative to the rigid gear.

        A tooth point is ``P = R(beta)(p - (r_m, 0)) + R(mat)(r_m + w, v)``
        with ``mat = phi (z_b - z_g)/z_b`` and ``beta = mat + theta``, so
        ``|dP/dphi| <= |beta'| max|p - (r_m, 0)| + |mat'| |(r_m + w, v)| + |(w', v')|``
        exactly, from the law's derivatives. Taken at every sample, with 10 %
        for the variation between neighbouring samples (they are < 1e-3 rad
        apart; the derivatives change by far less than 10 % over that).
        """
        st = self.law(z).state(np.asarray(phi, dtype=float))
        r_m = self.drive.r_m
        m1 = (self.z_b - self.z_g) / self.z_b
        # the section's tooth offset moves every tooth point by it along the centre line (docs/models.md 13.4)
        lever = float(np.hypot(self.flex_local[:, 0] - r_m, self.flex_local[:, 1]).max()) + abs(
            self.law(z).tooth_offset
        )
        v = np.abs(m1 + st.dtheta) * lever + abs(m1) * np.hypot(r_m + st.w, st.v) + np.hypot(st.dw, st.dv)
        return 1.1 * float(v.max())

    def radial_bound(self, pts: np.ndarray) -> np.ndarray:
        """Lower bound of the clearance from radii alone: > 0 when the tooth cannot reach rigid material."""
        R = np.hypot(pts[..., 0], pts[..., 1])
        return R.min(axis=1) - self.r_tip_b if self.external else self.r_tip_b - R.max(axis=1)

    def tip_radial(self, rot: np.ndarray, shift: np.ndarray) -> np.ndarray:
        """Exact radial gap ``(K,)`` between the placed tip arc and the rigid tip circle (> 0: radially clear).

        The tip arc is centred on the tooth frame's origin, which lands on
        ``shift``: its farthest (nearest) point from the gear axis lies along
        (against) ``shift`` if that direction falls within the arc, else at
        an end (docs/models.md 5, entry gap).
        """
        arc = self.tip_arc
        if arc is None:  # no tip arc (never for the built-in forms): fall back to the tip vertices
            return self.radial_bound(transform(self.flex_tip_local, rot, shift))
        c = np.hypot(shift[:, 0], shift[:, 1])
        psi = np.arctan2(shift[:, 1], shift[:, 0])
        lo_t, hi_t = sorted((arc.t0, arc.t1))
        want = psi if not self.external else psi + pi  # outermost point (internal deformation), innermost (external)
        rel = (want - rot - lo_t) % (2 * pi)
        inside = rel <= hi_t - lo_t
        ends = []
        for t in (lo_t, hi_t):
            ends.append(
                np.hypot(shift[:, 0] + arc.radius * np.cos(rot + t), shift[:, 1] + arc.radius * np.sin(rot + t))
            )
        if self.external:
            R = np.where(inside, np.abs(arc.radius - c), np.minimum(*ends))
            return R - self.r_tip_b
        R = np.where(inside, c + arc.radius, np.maximum(*ends))
        return self.r_tip_b - R

    def clearance_to(self, rot, shift, j, area: bool = False, flex_geoms=None):
        """Signed clearance of flexspline teeth at poses ``(rot, shift)`` to rigid teeth ``j`` (polygons)."""
        return signed_clearance(
            self.flex,
            rot,
            shift,
            self.rigid,
            self.rigid_rot[j],
            self.rigid_shift[j],
            b_geoms=self.rigid_geoms[j],
            area=area,
            a_geoms=flex_geoms,
        )

    def apart_to(self, rot, shift, j):
        """Distance between the curves of flexspline teeth at poses ``(rot, shift)`` and rigid teeth ``j``, known to
        be apart: ``(distance (K,), solved (K,), flexspline point (K, 2), rigid point (K, 2))``, the points in the
        rigid tooth's frame (:func:`wgcad.clearance.refine.apart_pairs`)."""
        j = np.atleast_1d(j)
        f, r = self.flex, self.rigid
        return apart_pairs(self.flex_exact, f.local, rot, shift, self.rigid_exact, r.local, r.polygon, *self._rigid(j))

    def exact_to(self, rot, shift, j, apart=None):
        """Signed clearance of flexspline teeth at poses ``(rot, shift)`` to rigid teeth ``j`` on the exact curves
        (``apart``: the pairs known to be apart, optional).

        Returns ``(value (K,), side (K,), point (K, 2))`` of :func:`wgcad.clearance.refine.refine_pairs`.
        """
        j = np.atleast_1d(j)
        f, r = self.flex, self.rigid
        flex = (self.flex_exact, f.local, f.polygon, rot, shift)
        return refine_pairs(*flex, self.rigid_exact, r.local, r.polygon, *self._rigid(j), apart=apart)

    def _rigid(self, j):
        """Poses of rigid teeth ``j`` and the refinement's seed margin (twice the polygon-curve gap of a pair)."""
        return self.rigid_rot[j], self.rigid_shift[j], 2.0 * self.chord_gap


def tooth_clearance(
    scene: Scene, phi, z=None, third: bool = True, area: bool = False, exact: bool = False
) -> PairFigures:
    """Signed clearance of a tooth at angles ``phi`` to the rigid teeth below and above it (and the third nearest).

    Returns the figures of every angle (:class:`PairFigures`, with ``area``
    the lower and upper overlap areas). With ``exact`` the figures of every
    pair that can hold the minimum are refined on the exact curves
    (:func:`refine_min`).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    rot, shift = scene.pose(phi, z)
    out = clearance_at_poses(scene, rot, shift, third=third, area=area)
    return refine_min(scene, rot, shift, out) if exact else out


def tooth_clearance_sections(
    scene: Scene, phi: np.ndarray, zi: np.ndarray, zs: list, exact: bool = False, pairs: bool = False
):
    """Smallest clearance of teeth at angles ``phi[k]`` in sections ``zs[zi[k]]``, in one batch, ``(K,)``; with
    ``pairs`` also each pair's ``(K, 3)`` (lower, upper, third)."""
    rot, shift = scene.pose_sections(phi, zi, zs)
    out = clearance_at_poses(scene, rot, shift)
    if exact:
        out = refine_min(scene, rot, shift, out)
    if pairs:
        return out.min, out.pairs()
    return out.min


def refine_min(
    scene: Scene, rot: np.ndarray, shift: np.ndarray, det: PairFigures, gap: float | None = None
) -> PairFigures:
    """Refine on the exact curves every pair of :func:`clearance_at_poses` that can hold a tooth's minimum.

    A pair's exact figure is within ``scene.chord_gap`` of its polygon one,
    so only pairs whose polygon figure is within twice that of the tooth's
    smallest are refined; the others keep their polygon figures (they
    cannot be the minimum; ``gap``: the polygons' own where ``det`` comes from finer
    polygons than the scene's). Returns ``det`` with the refined figures and ``min``.
    """
    gap = scene.chord_gap if gap is None else gap
    figs = [np.asarray(v, dtype=float) for v in (det.lower, det.upper, det.third)]
    rigid = (det.lo, det.up, det.th)
    needs = [np.nonzero(np.isfinite(v) & (v <= det.min + 2.0 * gap))[0] for v in figs]
    # every pair of every kind in one call: the refinement's cost is per call more than per pair
    allk = np.concatenate(needs)
    allj = np.concatenate([j[need] for j, need in zip(rigid, needs)])
    # a pair whose polygon figure exceeds the polygons' gap is apart on the curves too
    apart = np.concatenate([v[need] > gap for v, need in zip(figs, needs)])
    ex = scene.exact_to(rot[allk], shift[allk], allj, apart=apart)[0] if allk.size else np.zeros(0)
    at = 0
    for i, need in enumerate(needs):
        figs[i] = figs[i].copy()
        figs[i][need] = ex[at : at + need.size]
        at += need.size
    lower, upper, third = figs
    return replace(det, lower=lower, upper=upper, third=third, min=np.minimum(np.minimum(lower, upper), third))


def clearance_at_poses(
    scene: Scene, rot: np.ndarray, shift: np.ndarray, third: bool = True, area: bool = False, need=None
) -> PairFigures:
    """:func:`tooth_clearance` for teeth given by their poses (rigid frame).

    ``need (K, 3)`` bool, optional: which of the lower, upper and third
    pairs to measure (the others read inf; not with ``area``).
    """
    lo, up, th = scene.neighbours(shift, rot)
    pts = transform(scene.flex_local, rot, shift)
    geoms = shapely.polygons(pts)  # built once, measured against every neighbour
    figs, areas = [], [None, None]
    for col, idx in enumerate((lo, up)):
        if need is not None:
            k = np.nonzero(need[:, col])[0]
            val = np.full(len(rot), np.inf)
            val[k] = scene.clearance_to(rot[k], shift[k], idx[k], flex_geoms=geoms[k])
            figs.append(val)
            continue
        res = scene.clearance_to(rot, shift, idx, area=area, flex_geoms=geoms)
        if area:
            figs.append(res[0])
            areas[col] = res[1]
        else:
            figs.append(res)
    lower, upper = figs
    best = np.minimum(lower, upper)
    third_v = np.full(len(rot), np.inf)
    if third:
        # the third tooth lies beyond a bracketing one: 2 R sin(dphi/2) bounds its distance,
        # with dphi the angular gap between the tooth and the third tooth's flank extent
        R = np.hypot(pts[..., 0], pts[..., 1])
        ang = np.arctan2(pts[..., 1], pts[..., 0])
        tc = scene.rigid_rot[th]
        gap = np.abs((ang - tc[:, None] + pi) % (2 * pi) - pi).min(axis=1) - pi / scene.z_b
        r_lo = np.minimum(R.min(axis=1), scene.rigid_r_min)
        lb = 2.0 * r_lo * np.sin(np.clip(gap, 0.0, None) / 2.0)
        # polygons lie within the chord tolerance of the curves: the bound is widened by that
        near = lb < best + scene.chord_gap
        if need is not None:
            near &= need[:, 2]
        k = np.nonzero(near)[0]
        if k.size:
            third_v[k] = scene.clearance_to(rot[k], shift[k], th[k], flex_geoms=geoms[k])
    return PairFigures(lower, upper, third_v, np.minimum(best, third_v), lo, up, th, *areas)


def classify(scene: Scene, pts: np.ndarray, rigid_idx: int, phi: float, z) -> str:
    """Where on the flexspline tooth the closest approach lies: tip, working/non-working flank, root."""
    a = shapely.Polygon(pts)
    b = scene.rigid_geoms[rigid_idx]
    if a.intersects(b):
        inter = a.intersection(b)
        p = np.asarray(inter.representative_point().coords[0]) if not inter.is_empty else np.asarray(pts[0])
    else:
        p = np.asarray(shapely.shortest_line(a, b).coords[0])
    # back to the tooth frame: undo the frame rotation, the tooth rotation and translation
    law = scene.law(z)
    mat = phi * (scene.z_b - scene.z_g) / scene.z_b
    origin, ang = tooth_frames(law, np.array([phi]), scene.drive.r_m)
    fr = mat - phi
    c, s = np.cos(-fr), np.sin(-fr)
    q = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]]) - origin[0]
    c, s = np.cos(-ang[0]), np.sin(-ang[0])
    loc = np.array([c * q[0] - s * q[1], s * q[0] + c * q[1]]) + [scene.drive.r_m, 0.0]
    R = float(np.hypot(*loc))
    g = scene.drive.flex
    m = g.spec.module
    tip_zone = abs(R - g.r_a) < 0.05 * m
    root_zone = (
        abs(R - g.r_f) < (g.spec.fillet_coef + 0.05) * m
        if g.spec.form in ("involute", "double_arc")
        else abs(R - g.r_f) < 0.05 * m
    )
    if tip_zone:
        return "tip"
    if root_zone:
        return "root"
    side = "upper" if loc[1] > 0 else "lower"
    return "working flank" if side == scene.working else "non-working flank"
