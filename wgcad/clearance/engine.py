"""The 2D clearance engine: every flexspline tooth against its nearest rigid teeth over generator angles and sections (theory.md 5, 7).

Why it can skip work (each switchable, each tested against the full computation):

* **mesh period** (theory.md 7): for perfect gears the state of a tooth
  depends only on its angle ``phi`` from the generator's major axis. A tooth
  at ``phi`` has its material angle at ``phi (z_b - z_g)/z_b`` modulo a rigid
  pitch, so every (generator angle, tooth) sample is a sample of one
  function ``c(phi)`` per section, and equal ``phi`` need one evaluation.
* **identical waves**: ``c`` is periodic in ``2 pi / n_w`` (the law is, and
  a wave shifts the rigid teeth by ``(z_b - z_g)/n_w`` whole pitches), so
  ``phi`` folds into one wave. With tooth counts that are multiples of
  ``n_w`` the folded samples coincide; with odd counts they interleave.
* **mirror symmetry**: teeth are symmetric and every deformation law is
  even in ``phi``, and a tooth at ``-phi`` sits at ``-phi (z_b - z_g)/z_b``
  against the rigid teeth: the scene at ``-phi`` is the mirror image of the
  one at ``phi``, so ``c(-phi) = c(phi)`` with the two flanks swapped.
* **culling**: a tooth whose outermost point is inside the rigid tip circle
  (internal deformation) is radially separated from all rigid material by
  at least the gap between the two radii; it is evaluated only if that
  bound is below the minimum found. The third-nearest rigid tooth is
  evaluated only where ``2 R sin(dphi/2)`` does not already exceed the
  clearance to the two bracketing teeth.
* **branch and bound**: ``c`` is Lipschitz in ``phi`` (a rigid motion moves
  the tooth by at most ``V dphi``, with ``V`` bounded from the law's
  derivatives, :meth:`Scene.speed_bound`), so a sample between two
  evaluated ones is bounded below by ``max(c_i - V |phi - phi_i|)``; only
  samples whose bound is below the running minimum are evaluated, on
  successively finer strides.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import pi

import numpy as np
import shapely

from .. import constants
from ..kinematics import gear_ratios
from ..placement import pose_from_displacements, tooth_frames, tooth_pose, transform
from .distance import Template, signed_clearance
from .refine import ExactTooth, refine_pairs

__all__ = ["AuditSettings", "AuditResult", "Scene", "tooth_clearance", "audit", "brute_force_min"]


@dataclass(frozen=True)
class AuditSettings:
    """What an audit computes.

    Attributes
    ----------
    angles : (A,) float
        Generator angles relative to the rigid gear, rad.
    sections : (S,) float
        Axial positions of the cross-sections, mm from the open end.
    use_period, use_waves, use_mirror, cull, bound : bool
        The work-skipping shortcuts (module docstring); all on by default.
    interference_tol : float
        Penetration (mm) reported as contact rather than interference.
    refine : bool
        Refine the figures on the exact tooth curves (:mod:`wgcad.clearance.refine`);
        off: the polygons' figures (within about twice the chord tolerance).
    """

    angles: np.ndarray
    sections: np.ndarray
    use_period: bool = True
    use_waves: bool = True
    use_mirror: bool = True
    cull: bool = True
    bound: bool = True
    interference_tol: float = constants.INTERFERENCE_TOL
    refine: bool = True


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
        # exact pieces of both teeth, and how far a polygon figure can be from the curves' one:
        # every vertex is on its curve and every chord within tol of it, so a distance, and a
        # depth measured from vertices, moves by at most tol per tooth (docs/models.md 5)
        self.flex_exact = ExactTooth(drive.flex, self.flex.local)
        self.rigid_exact = ExactTooth(drive.rigid, self.rigid.local)
        self.chord_gap = 2.0 * drive.tol
        tip = [p for p in drive.flex.pieces if p.kind == "arc" and np.allclose(p.center, 0.0, atol=1e-12)
               and abs(p.radius - drive.flex.r_a) <= 1e-9 * drive.flex.r_a]
        self.tip_arc = tip[0] if tip else None
        self.entry_sign = rot  # teeth enter engagement on the side the generator turns toward
        self._laws = {}

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
            return pose_from_displacements(phi, f * st.w, f * st.v, f * st.theta, self.drive.r_m, mat - phi)
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
        lever = float(np.hypot(self.flex_local[:, 0] - r_m, self.flex_local[:, 1]).max())
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
            ends.append(np.hypot(shift[:, 0] + arc.radius * np.cos(rot + t), shift[:, 1] + arc.radius * np.sin(rot + t)))
        if self.external:
            R = np.where(inside, np.abs(arc.radius - c), np.minimum(*ends))
            return R - self.r_tip_b
        R = np.where(inside, c + arc.radius, np.maximum(*ends))
        return self.r_tip_b - R

    def clearance_to(self, rot, shift, j, area: bool = False, flex_geoms=None):
        """Signed clearance of flexspline teeth at poses ``(rot, shift)`` to rigid teeth ``j`` (polygons)."""
        return signed_clearance(self.flex, rot, shift, self.rigid, self.rigid_rot[j], self.rigid_shift[j],
                                b_geoms=self.rigid_geoms[j], area=area, a_geoms=flex_geoms)

    def exact_to(self, rot, shift, j):
        """Signed clearance of flexspline teeth at poses ``(rot, shift)`` to rigid teeth ``j`` on the exact curves.

        Returns ``(value (K,), side (K,), point (K, 2))`` of :func:`wgcad.clearance.refine.refine_pairs`.
        """
        j = np.atleast_1d(j)
        return refine_pairs(self.flex_exact, self.flex.local, self.flex.polygon, rot, shift,
                            self.rigid_exact, self.rigid.local, self.rigid.polygon, self.rigid_rot[j], self.rigid_shift[j],
                            margin=2.0 * self.chord_gap)


def tooth_clearance(scene: Scene, phi, z=None, third: bool = True, area: bool = False, exact: bool = False) -> dict:
    """Signed clearance of a tooth at angles ``phi`` to the rigid teeth below and above it (and the third nearest).

    Returns
    -------
    dict of (K,) arrays: ``lower``, ``upper``, ``third`` (mm, negative =
    penetration depth), ``min``, ``lo``/``up`` rigid tooth indices, and with
    ``area`` the overlap areas ``lower_area``, ``upper_area``. With
    ``exact`` the figures of every pair that can hold the minimum are
    refined on the exact curves (:func:`refine_min`).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    rot, shift = scene.pose(phi, z)
    out = clearance_at_poses(scene, rot, shift, third=third, area=area)
    return refine_min(scene, rot, shift, out) if exact else out


def tooth_clearance_sections(scene: Scene, phi: np.ndarray, zi: np.ndarray, zs: list, exact: bool = False) -> np.ndarray:
    """Smallest clearance of teeth at angles ``phi[k]`` in sections ``zs[zi[k]]``, in one batch, ``(K,)``."""
    rot, shift = scene.pose_sections(phi, zi, zs)
    out = clearance_at_poses(scene, rot, shift)
    return refine_min(scene, rot, shift, out)["min"] if exact else out["min"]


def refine_min(scene: Scene, rot: np.ndarray, shift: np.ndarray, det: dict) -> dict:
    """Refine on the exact curves every pair of :func:`clearance_at_poses` that can hold a tooth's minimum.

    A pair's exact figure is within ``scene.chord_gap`` of its polygon one,
    so only pairs whose polygon figure is within twice that of the tooth's
    smallest are refined; the others keep their polygon figures (they
    cannot be the minimum). Adds ``refined_lower``/``_upper``/``_third``
    (bool) and ``point_lower``... (the extremal point, rigid-tooth frame
    for side 0) to ``det`` and updates the figures and ``min``.
    """
    out = dict(det)
    gap = scene.chord_gap
    best = det["min"]
    idx = {"lower": det["lo"], "upper": det["up"]}
    if "th" in det:
        idx["third"] = det["th"]
    needs = {}
    for key in idx:
        val = np.asarray(det[key], dtype=float)
        needs[key] = np.nonzero(np.isfinite(val) & (val <= best + 2.0 * gap))[0]
    # every pair of every kind in one call: the refinement's cost is per call more than per pair
    allk = np.concatenate([needs[k] for k in idx])
    allj = np.concatenate([idx[k][needs[k]] for k in idx])
    ex = scene.exact_to(rot[allk], shift[allk], allj)[0] if allk.size else np.zeros(0)
    at = 0
    for key in idx:
        val = np.asarray(det[key], dtype=float).copy()
        need = needs[key]
        val[need] = ex[at : at + need.size]
        at += need.size
        done = np.zeros(len(val), dtype=bool)
        done[need] = True
        out[key] = val
        out[f"refined_{key}"] = done
    out["min"] = np.minimum(np.minimum(out["lower"], out["upper"]), out.get("third", np.inf))
    return out


def clearance_at_poses(scene: Scene, rot: np.ndarray, shift: np.ndarray, third: bool = True, area: bool = False) -> dict:
    """:func:`tooth_clearance` for teeth given by their poses (rigid frame)."""
    lo, up, th = scene.neighbours(shift, rot)
    pts = transform(scene.flex_local, rot, shift)
    geoms = shapely.polygons(pts)  # built once, measured against every neighbour
    out = {}
    for key, idx in (("lower", lo), ("upper", up)):
        res = scene.clearance_to(rot, shift, idx, area=area, flex_geoms=geoms)
        if area:
            out[key], out[f"{key}_area"] = res
        else:
            out[key] = res
    best = np.minimum(out["lower"], out["upper"])
    out["third"] = np.full(len(rot), np.inf)
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
        need = np.nonzero(lb < best + scene.chord_gap)[0]
        if need.size:
            out["third"][need] = scene.clearance_to(rot[need], shift[need], th[need], flex_geoms=geoms[need])
    out["min"] = np.minimum(best, out["third"])
    out["lo"], out["up"], out["th"] = lo, up, th
    return out


def _sample_phi(scene: Scene, angles: np.ndarray) -> np.ndarray:
    """Tooth angles from the major axis for every (generator angle, tooth): ``(A, z_g)``, rad."""
    k = np.arange(scene.z_g)
    mat = 2 * pi * k[None, :] / scene.z_g + angles[:, None] / scene.ratios["u_hg"]
    return mat - angles[:, None]


def _fold(phi: np.ndarray, period: float) -> np.ndarray:
    return (phi + 0.5 * period) % period - 0.5 * period


class _SectionSearch:
    """Branch and bound for the smallest sampled clearance of one section (module docstring)."""

    def __init__(self, scene: Scene, phi_u: np.ndarray, z, settings: AuditSettings):
        self.scene, self.phi, self.z, self.settings = scene, phi_u, z, settings
        n = len(phi_u)
        self.value = np.full(n, np.nan)
        self.evaluated = np.zeros(n, dtype=bool)
        self.radial = scene.radial_bound(scene.place(phi_u, z, local=scene.flex_tip_local))
        self.lower = self.radial.copy()
        zone = self.radial <= 0.0 if settings.cull else np.ones(n, dtype=bool)
        self.zone_mask = zone
        self.zone = np.nonzero(zone)[0]
        self.culled = 0
        self.V = 0.0
        # a sample whose polygon figure is within twice the polygon-curve difference of the
        # best may still be the exact minimum: nothing within that margin is skipped
        self.margin = 2.0 * scene.chord_gap if settings.refine else 0.0

    def prepare_bound(self) -> None:
        """Speed bound for branch and bound (only worth it with many samples)."""
        if self.settings.bound and self.zone.size >= 64:
            self.V = self.scene.speed_bound(self.phi[self.zone], self.z)

    def best(self) -> float:
        return float(np.nanmin(self.value)) if self.evaluated.any() else np.inf

    def coarse(self) -> np.ndarray:
        """Indices of the coarse pass: every sample without bounding, else every ``stride``-th in the zone."""
        self.stride = max(1, min(256, self.zone.size // 16))
        if not self.settings.bound or self.V == 0.0:
            return self.zone
        return self.zone[:: self.stride]

    def candidates(self, stride: int, best: float) -> np.ndarray:
        """Samples on this stride whose lower bound is below ``best`` (indices into :attr:`phi`)."""
        if self.V == 0.0 or stride >= self.stride:
            return np.zeros(0, dtype=int)
        zi, pz = self.zone, self.phi[self.zone]
        cand = np.arange(0, zi.size, stride)
        cand = cand[~self.evaluated[zi[cand]]]
        if cand.size == 0:
            return np.zeros(0, dtype=int)
        # bound from the nearest evaluated samples on both sides
        ev = np.nonzero(self.evaluated[zi])[0]
        pos = np.searchsorted(ev, cand)
        left = ev[np.clip(pos - 1, 0, len(ev) - 1)]
        right = ev[np.clip(pos, 0, len(ev) - 1)]
        vl = self.value[zi[left]] - self.V * np.abs(pz[cand] - pz[left])
        vr = self.value[zi[right]] - self.V * np.abs(pz[right] - pz[cand])
        lb = np.maximum(np.maximum(vl, vr), self.lower[zi[cand]])
        self.lower[zi[cand]] = lb
        return zi[cand[lb < best + self.margin]]

    def culled_needed(self, best: float) -> np.ndarray:
        """Culled samples whose radial bound does not clear ``best``: they must be evaluated."""
        out = np.nonzero(~self.zone_mask)[0]
        need = out[self.radial[out] < best + self.margin]
        self.culled = int(out.size - need.size)
        return need


#: samples evaluated per batch: large enough to amortise the per-call cost, small enough for
#: the progress bar to move every few tens of milliseconds
_CHUNK = 4096


def _evaluate(scene: Scene, searches: list, picks: list, zs: list, done=None) -> float:
    """Evaluate the picked samples of every section in batches; return the best value so far."""
    phis = np.concatenate([r.phi[ix] for r, ix in zip(searches, picks)])
    if phis.size:
        zi = np.concatenate([np.full(len(ix), i) for i, ix in enumerate(picks)])
        vals = np.empty(len(phis))
        for a in range(0, len(phis), _CHUNK):
            b = min(a + _CHUNK, len(phis))
            vals[a:b] = tooth_clearance_sections(scene, phis[a:b], zi[a:b], zs)
            if done is not None:
                done(b / len(phis))
        at = 0
        for r, ix in zip(searches, picks):
            n = len(ix)
            r.value[ix] = vals[at : at + n]
            r.lower[ix] = vals[at : at + n]
            r.evaluated[ix] = True
            at += n
    return min(r.best() for r in searches)


@dataclass
class AuditResult:
    """Figures of an audit (lengths mm, angles rad inside; :meth:`to_json` converts at the edge)."""

    settings: dict
    min_clearance: float
    worst: dict
    entry_gap: float
    entry: dict
    backlash: float
    backlash_range: dict
    interference: bool
    interference_tol: float
    counts: dict
    settings_angles: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    #: unrounded tooth angles (rad) of the tightest sample, the entry crossing and the pinch
    raw: dict = field(default_factory=dict)
    elapsed_s: float = 0.0

    def to_json(self) -> dict:
        """The JSON document (shaped in :func:`wgcad.report.audit.audit_json`)."""
        from ..report.audit import audit_json

        return audit_json(self)


def _classify(scene: Scene, pts: np.ndarray, rigid_idx: int, phi: float, z) -> str:
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
    root_zone = abs(R - g.r_f) < (g.spec.fillet_coef + 0.05) * m if g.spec.form == "involute" else abs(R - g.r_f) < 0.05 * m
    if tip_zone:
        return "tip"
    if root_zone:
        return "root"
    side = "upper" if loc[1] > 0 else "lower"
    return "working flank" if side == scene.working else "non-working flank"


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
        # the exact curves' minimum in the bracket: nested 9-point grids, each a quarter of the last,
        # the first across the whole bracket (the polygons' minimum can sit elsewhere in it)
        w = 0.5 * (hi[k] - lo[k])
        p_c = 0.5 * (hi[k] + lo[k])
        c_min = np.inf
        for _ in range(6):
            g = np.clip(p_c + np.linspace(-w, w, 9), lo[k], hi[k])
            v = tooth_clearance_sections(scene, sgn * g, np.full(9, k), zs, exact=True)
            j = int(np.argmin(v))
            if v[j] < c_min:
                c_min, p_c = float(v[j]), float(g[j])
            w /= 4.0
        p_min = p_c
    z_min = zs[k]
    p_min = sgn * p_min
    det = tooth_clearance(scene, np.array([p_min]), z_min)
    side = "lower" if det["lower"][0] <= det["upper"][0] else "upper"
    rot, shift = scene.pose(np.array([p_min]), z_min)
    pts = transform(scene.flex_local, rot, shift)[0]
    loc = _classify(scene, pts, int(det["lo" if side == "lower" else "up"][0]), p_min, z_min)
    return c_min, p_min, z_min, loc


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


#: refinement: above this many candidate samples they are first sorted out on polygons _FINE
#: times finer (chord tolerance / 8: margin 8 times smaller), which costs one finer outline
#: (~30 ms) and a polygon pass, far less than refining hundreds of samples on the curves
_FINE_ABOVE = 48
_FINE = 8


def _ticker(progress):
    """``tick(fraction, stage)`` -> ``progress(done, total, stage)`` in thousandths of the whole audit's work."""
    if progress is None:
        return lambda frac, stage: None
    return lambda frac, stage: progress(int(round(1000 * min(max(frac, 0.0), 1.0))), 1000, stage)


#: share of an audit's run time spent in each stage (measured on D1, full revolution, 3 sections):
#: the progress fractions follow the work, not the stage count
_STAGES = {"clearance": (0.0, 0.70), "refine": (0.70, 0.80), "entry gap": (0.80, 0.86), "pinch": (0.86, 0.95), "backlash": (0.95, 1.0)}


def _stage(tick, name):
    a, b = _STAGES[name]
    return lambda f: tick(a + (b - a) * f, name)


def _canonical(scene: Scene, phi_all: np.ndarray, period: float, phi_w: float, z, exact: bool):
    """The worst spot folded to the nearest major axis: ``(phi >= 0, location, mirror location, sample index)``.

    Teeth and laws are symmetric: the tooth at ``-phi`` is the mirror image
    of the one at ``+phi`` with its flanks swapped, so both are named and
    the spot is reported at ``+|phi|`` whichever sample the search met
    first (issue 13: the printed spot no longer depends on the shortcuts).
    The sample is the first (generator angle, tooth) in order whose tooth
    angle folds to ``+|phi|`` (else ``-|phi|``).
    """
    a = abs(float(_fold(np.array([phi_w]), 2 * pi / scene.n_w)[0]))
    folded = _fold(phi_all.ravel(), 2 * pi / scene.n_w)
    hit = np.nonzero(np.abs(folded - a) <= 1e-9)[0]
    sgn = 1.0
    if hit.size == 0:
        hit = np.nonzero(np.abs(folded + a) <= 1e-9)[0]
        sgn = -1.0
    flat = int(hit[0]) if hit.size else int(np.argmin(np.abs(np.abs(folded) - a)))
    locs = []
    for p in (a, -a):
        det = tooth_clearance(scene, np.array([p]), z, exact=exact)
        side = min(("lower", "upper", "third"), key=lambda k: det[k][0])
        ridx = det["up"][0] if side == "upper" else det["lo"][0] if side == "lower" else det["th"][0]
        pts = scene.place(np.array([p]), z)[0]
        locs.append(_classify(scene, pts, int(ridx), p, z))
    return a, locs[0], locs[1], flat, sgn


def audit(drive, settings: AuditSettings, progress=None) -> AuditResult:
    """Clearance audit of a drive over generator angles and sections (2D engine, docs/models.md 5, 7).

    The polygons find the tightest samples (branch and bound with a margin
    for the polygon-curve difference); every sample that can be the
    minimum is then refined on the exact curves (``settings.refine``), and
    so are the entry gap and the pinch. ``progress``, if given, is called as
    ``progress(done, total, stage)`` with ``done/total`` the fraction of the
    audit's work done so far.
    """
    t0 = time.perf_counter()
    tick = _ticker(progress)
    scene = Scene(drive)
    angles = np.asarray(settings.angles, dtype=float)
    sections = [None] if not drive.coned else [float(z) for z in settings.sections]
    phi_all = _sample_phi(scene, angles)  # (A, z_g)
    period = 2 * pi / scene.n_w if settings.use_waves else 2 * pi
    key = _fold(phi_all, period)
    if settings.use_mirror:
        key = np.abs(key)
    n_samples = phi_all.size * len(sections)
    if settings.use_period:
        phi_u, inverse = np.unique(np.round(key, 12), return_inverse=True)
    else:
        phi_u, inverse = key.ravel(), np.arange(key.size)
    order = np.argsort(phi_u, kind="stable")
    phi_sorted = phi_u[order]
    results = [_SectionSearch(scene, phi_sorted, z, settings) for z in sections]
    for r in results:
        r.prepare_bound()
    st = _stage(tick, "clearance")
    st(0.0)
    # coarse pass over every section first: the best of any prunes all; then finer strides
    best = _evaluate(scene, results, [r.coarse() for r in results], sections, lambda f: st(0.3 * f))
    for step, stride in enumerate((64, 16, 4, 1)):
        best = _evaluate(scene, results, [r.candidates(stride, best) for r in results], sections,
                         lambda f, s=step: st(0.3 + 0.15 * (s + f)))
    best = _evaluate(scene, results, [r.culled_needed(best) for r in results], sections, lambda f: st(0.9 + 0.1 * f))
    best_poly = best
    # refinement on the exact curves of every sample that can hold the minimum
    stg = _stage(tick, "refine")
    stg(0.0)
    cand_s, cand_i, cand_v = [], [], []
    for si, r in enumerate(results):
        ev = np.nonzero(r.evaluated)[0]
        lim = best_poly + (2.0 * scene.chord_gap if settings.refine else 0.0)
        keep = ev[r.value[ev] <= lim]
        cand_s.append(np.full(keep.size, si))
        cand_i.append(keep)
        cand_v.append(r.value[keep])
    cand_s, cand_i, cand_v = np.concatenate(cand_s), np.concatenate(cand_i), np.concatenate(cand_v)
    o = np.argsort(cand_v, kind="stable")
    cand_s, cand_i, cand_v = cand_s[o], cand_i[o], cand_v[o]
    n_refined = 0
    n_fine = 0
    ref_scene = scene
    if settings.refine and len(cand_v) > _FINE_ABOVE:
        # many samples within the polygon-curve margin (a flat minimum): sort them out on polygons
        # FINE times finer first (cheap), whose margin is FINE times smaller, then refine the few left
        from ..drive import build_drive

        ref_scene = Scene(build_drive(drive.design, tol=drive.tol / _FINE))
        cand_v = tooth_clearance_sections(ref_scene, phi_sorted[cand_i], cand_s, sections)
        n_fine = len(cand_v)
        o = np.argsort(cand_v, kind="stable")
        cand_s, cand_i, cand_v = cand_s[o], cand_i[o], cand_v[o]
        keep = cand_v <= cand_v[0] + 2.0 * ref_scene.chord_gap
        cand_s, cand_i, cand_v = cand_s[keep], cand_i[keep], cand_v[keep]
    if settings.refine:
        exact_best, where = np.inf, (int(cand_s[0]), int(cand_i[0]))
        at = 0
        while at < len(cand_v):
            # a sample whose polygon figure less the polygon-curve difference is not below the best exact
            # figure cannot hold the minimum: stop there (candidates are in increasing order)
            if cand_v[at] - ref_scene.chord_gap >= exact_best:
                break
            # the 16 lowest first (they set the bar), then every remaining candidate in one batch:
            # the refinement's cost is per call, not per sample
            live = np.nonzero(cand_v[at:] - ref_scene.chord_gap < exact_best)[0] + at if at else np.arange(min(16, len(cand_v)))
            if live.size == 0:
                break
            sl = live
            vals = tooth_clearance_sections(scene, phi_sorted[cand_i[sl]], cand_s[sl], sections, exact=True)
            n_refined += len(vals)
            j = int(np.argmin(vals))
            if vals[j] < exact_best:
                exact_best, where = float(vals[j]), (int(cand_s[sl][j]), int(cand_i[sl][j]))
            at = int(sl[-1]) + 1 if at == 0 else len(cand_v)
            stg(at / len(cand_v))
        best = exact_best
    else:
        where = (int(cand_s[0]), int(cand_i[0]))
    si, i = where
    z_w = sections[si]
    phi_c, loc, mirror_loc, flat, sgn_c = _canonical(scene, phi_all, period, float(phi_sorted[i]), z_w, settings.refine)
    ai, k = divmod(flat, scene.z_g)
    phi_rep = sgn_c * phi_c
    detail = tooth_clearance(scene, np.array([phi_rep]), z_w, area=True)
    side_val = {"lower": detail["lower"][0], "upper": detail["upper"][0], "third": detail["third"][0]}
    side = min(side_val, key=side_val.get)
    area = detail.get(f"{side}_area", np.zeros(1))[0] if side != "third" else 0.0
    worst = {
        "clearance_um": round(1e3 * best, 4),
        "tooth": int(k),
        "generator_angle_deg": round(float(np.rad2deg(angles[ai])), 6),
        "tooth_angle_deg": round(float(np.rad2deg(phi_c)), 6),
        "section_z_mm": None if z_w is None else round(z_w, 6),
        "location": loc,
        "mirror": {"tooth_angle_deg": round(float(np.rad2deg(-phi_c)), 6), "location": mirror_loc},
        "sample_tooth_angle_deg": round(float(np.rad2deg(phi_rep)), 6),
        "overlap_area_um2": round(1e6 * float(area), 4),
        "polygon_clearance_um": round(1e3 * best_poly, 4),
    }
    ste = _stage(tick, "entry gap")
    ste(0.0)
    gaps = list(zip(entry_crossings(scene, sections, exact=settings.refine), sections))
    (eg, ephi), ez = min(gaps, key=lambda t: (np.inf if np.isnan(t[0][0]) else t[0][0]))
    crossed = bool(np.isfinite(eg))  # NaN: the tips never cross the rigid tip circle (no angle, no section)
    entry = {
        "tooth_angle_deg": round(float(np.rad2deg(ephi)), 6) if crossed else None,
        "section_z_mm": None if ez is None or not crossed else round(ez, 6),
        "side": "entry (+phi)" if scene.entry_sign > 0 else "entry (-phi)",
    }
    stp = _stage(tick, "pinch")
    stp(0.0)
    pinch = entry_pinch(scene, [(g[1], z) for g, z in gaps if np.isfinite(g[0])], exact=settings.refine) if crossed else None
    if pinch is None:
        pp = None
        entry.update({"pinch_um": None, "pinch_tooth_angle_deg": None, "pinch_section_z_mm": None,
                      "pinch_location": None, "tip_to_tip_risk": False})
    else:
        pc, pp, pz, ploc = pinch
        entry.update({
            "pinch_um": round(1e3 * pc, 4),
            "pinch_tooth_angle_deg": round(float(np.rad2deg(pp)), 6),
            "pinch_section_z_mm": None if pz is None else round(pz, 6),
            "pinch_location": ploc,
            # tip-to-tip jamming: the tooth tip meets a rigid tooth before its flank engages
            "tip_to_tip_risk": bool(pc < settings.interference_tol and ploc == "tip"),
        })
    _stage(tick, "backlash")(0.0)
    # backlash at the first requested generator angle, middle section
    z_mid = sections[len(sections) // 2]
    bl = [backlash(scene, float(angles[0]), z_mid)]
    tick(1.0, "done")
    evaluated = int(sum(r.evaluated.sum() for r in results))
    counts = {
        "samples": int(n_samples),
        "unique_tooth_angles": int(len(phi_u)),
        "sections": len(sections),
        "evaluated": evaluated,
        "culled": int(sum(r.culled for r in results)),
        "refined": int(n_refined),
        "fine_polygon": int(n_fine),
    }
    bw = drive.design.drive.face_width
    ends = (not drive.coned) or (min(sections) <= 1e-9 and max(sections) >= bw - 1e-9)
    rs = {
        "engine": "2d",
        "angles": int(len(angles)),
        "angle_step_deg": round(float(np.rad2deg(np.median(np.diff(angles)))), 6) if len(angles) > 1 else None,
        "sections_z_mm": [None if z is None else round(z, 6) for z in sections],
        "sections_note": ("identical sections (no coning): one computed" if not drive.coned else
                          "coned: every section computed" + ("" if ends else "; the face ends were NOT checked")),
        "face_ends_checked": bool(ends),
        "mesh_period": bool(settings.use_period),
        "identical_waves": bool(settings.use_waves),
        "mirror_symmetry": bool(settings.use_mirror),
        "culling": bool(settings.cull),
        "branch_and_bound": bool(settings.bound),
        "chord_tol_um": round(1e3 * drive.tol, 6),
        "refined": bool(settings.refine),
        "refine_tol_um": round(1e3 * constants.REFINE_TOL, 6) if settings.refine else None,
        "error_side": ("figures on the exact curves, within refine_tol_um either side" if settings.refine else
                       "polygon figures: chords lie inside convex and outside concave curve parts, "
                       "so each figure is within 2 x chord_tol_um of the exact one, either side"),
        "working_flank": scene.working,
        "rigid_pitch_radius_mm": drive.rigid.r,
    }
    res = AuditResult(
        settings=rs,
        min_clearance=best,
        worst=worst,
        entry_gap=eg,
        entry=entry,
        backlash=float(min(bl)),
        backlash_range={"generator_angle_deg": round(float(np.rad2deg(angles[0])), 6), "section_z_mm": None if z_mid is None else round(z_mid, 6)},
        interference=best < -settings.interference_tol,
        interference_tol=settings.interference_tol,
        counts=counts,
        settings_angles=angles,
        raw={"worst_phi": phi_c, "entry_phi": ephi, "pinch_phi": pp, "min_clearance_polygon": best_poly},
    )
    res.elapsed_s = time.perf_counter() - t0
    return res


def brute_force_min(drive, angles: np.ndarray, sections) -> float:
    """Reference: every flexspline tooth against its 3 nearest rigid teeth at every angle and section, no skips."""
    scene = Scene(drive)
    best = np.inf
    secs = [None] if not drive.coned else list(sections)
    for z in secs:
        law = scene.law(z)
        for phi_h in np.asarray(angles, dtype=float):
            k = np.arange(scene.z_g)
            mat = 2 * pi * k / scene.z_g + phi_h / scene.ratios["u_hg"]
            rot, shift = tooth_pose(law, mat - phi_h, drive.r_m, frame_angle=phi_h)
            lo, up, th = scene.neighbours(shift, rot)
            for idx in (lo, up, th):
                best = min(best, float(scene.clearance_to(rot, shift, idx).min()))
    return best


def clearance_profile(scene: Scene, sections, step_deg: float = 0.1) -> dict:
    """Per-tooth clearance against the tooth's angle from the major axis over one wave, per flank and section.

    This is the function ``c(phi)`` every tooth follows (perfect gears,
    theory.md 7): the picture designers reason with. Working flank: the
    side facing the rigid tooth that carries the load (:attr:`Scene.working`).

    Returns
    -------
    dict with ``phi`` (P,) rad and ``sections``: list of
    ``{"z", "working", "nonworking"}`` arrays (mm).
    """
    half = pi / scene.n_w
    phi = np.linspace(-half, half, int(round(2 * np.rad2deg(half) / step_deg)) + 1)
    out = []
    for z in sections:
        res = tooth_clearance(scene, phi, z, third=False)
        w, n = ("upper", "lower") if scene.working == "upper" else ("lower", "upper")
        out.append({"z": z, "working": res[w], "nonworking": res[n]})
    return {"phi": phi, "sections": out}


def clearance_vs_angle(scene: Scene, profile: dict, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smallest clearance over the teeth at each generator angle, per flank (mm), read off the profile.

    Each tooth's clearance at a generator angle is the profile at its tooth
    angle (mesh period), linearly interpolated between profile points: a
    picture, not an exact figure (the audit's minimum is exact).
    """
    phi = _fold(_sample_phi(scene, np.asarray(angles, dtype=float)), 2 * pi / scene.n_w)
    w = np.full(len(angles), np.inf)
    n = np.full(len(angles), np.inf)
    for sec in profile["sections"]:
        w = np.minimum(w, np.interp(phi, profile["phi"], sec["working"]).min(axis=1))
        n = np.minimum(n, np.interp(phi, profile["phi"], sec["nonworking"]).min(axis=1))
    return w, n
