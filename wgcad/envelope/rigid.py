"""A rigid gear whose flanks are conjugate to the flexspline's teeth under the design's law (docs/models.md 13).

The flank is :func:`wgcad.envelope.space.conjugate_flank`: its exact points
joined by one tangent-continuous cubic Hermite spline with the envelope's tangents (smooth,
one piece for the exports, and closer to the envelope than the chords, which
lie within 5 nm of it). Where the flexspline tooth
never touches, the tooth is completed by stated rules: from the tip circle to
the flank's first point the tip circle is raised to that point (the tooth's
path there is bounded by its own corners, which a radial wall did not clear),
beyond its last point the tooth's corners trace paths, not envelopes: the wall
steps along the circle of the flank's last point to the largest angle the
tooth reaches beyond it (plus 0.2 um), then runs radially to the root circle; tip and root are arcs about
the gear's centre. The gear keeps
the design's tooth count, module and radii; only its flanks change.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import pi

import numpy as np
import shapely

from wgcad.profiles import pieces as pc
from wgcad.profiles.gear import Gear

from .conjugate import flank_pieces
from .space import conjugate_flank

__all__ = ["conjugate_rigid_gear"]


def _turn(p: np.ndarray, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return p @ np.array([[c, s], [-s, c]])


#: the wall beyond the conjugate flank clears the tooth's sampled path by this much, mm (0.2 um: the samples are
#: 0.25 um apart along the tooth and 2e-4 rad of generator angle apart, so the path between them strays less)
WALL_MARGIN = 2e-4


def _reaching(pts: np.ndarray, rot: np.ndarray, shift: np.ndarray, r_last: float):
    """The poses at which some of the points ``pts`` can lie beyond the radius ``r_last``: every 8th point is placed,
    and every point lies within ``reach`` of one of those (a rigid motion keeps distances), so a pose whose placed
    points all stay within ``r_last - reach`` has none beyond it. The others are the only ones that count. First,
    likewise, the poses whose placed circle about all the points stays within ``r_last`` (most of them) are left."""
    c0 = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    rho = float(np.hypot(*(pts - c0).T).max())
    far = np.hypot(
        np.cos(rot) * c0[0] - np.sin(rot) * c0[1] + shift[:, 0], np.sin(rot) * c0[0] + np.cos(rot) * c0[1] + shift[:, 1]
    )
    rot, shift = rot[far + rho > r_last], shift[far + rho > r_last]
    n = len(pts)
    i = np.arange(n)
    i0 = (i // 8) * 8
    i1 = np.minimum(i0 + 8, n - 1)
    reach = float(np.minimum(np.hypot(*(pts - pts[i0]).T), np.hypot(*(pts - pts[i1]).T)).max())
    sub = pts[::8]
    c, s = np.cos(rot)[:, None], np.sin(rot)[:, None]
    r = np.hypot(c * sub[:, 0] - s * sub[:, 1] + shift[:, 0, None], s * sub[:, 0] + c * sub[:, 1] + shift[:, 1, None])
    keep = r.max(axis=1) + reach > r_last
    return rot[keep], shift[keep]


def _tip_wall(drive, cf, side: int = 1, clearance: float = 0.0, last=None) -> np.ndarray:
    """The wall's step beyond the flank's last point (rigid frame; none when the flank's own end angle is enough):
    the tooth's corners there trace paths, not envelopes (D1: the tip corner passed a radial wall by 2.3 um), so
    the wall steps along the circle of the last point to the largest angle the tooth reaches beyond it (1 um bands
    of radius) plus :data:`WALL_MARGIN`, and then runs radially."""
    last = cf.points[-1] if last is None else np.asarray(last, float)  # the flank's last point (set back, if it is)
    r_last = float(np.hypot(*last))
    pts = np.concatenate(
        [p.point(np.linspace(p.t0, p.t1, max(2, int(p.length() / 2.5e-4)))) for p in flank_pieces(drive.flex, side)]
    )
    pts = pts[np.hypot(*pts.T) > drive.flex.r_f + 0.5 * (drive.flex.r_a - drive.flex.r_f)]  # the tooth's upper half
    t = np.arange(-0.6, 0.6, 2e-4)
    rot, shift = cf.motion.pose(t)
    rot, shift = _reaching(pts, rot, shift, r_last)
    r_all, a_all = [], []
    step = max(1, (1 << 19) // len(pts))  # poses a block: each (poses, points) array near 4 MB
    for k in range(0, len(rot), step):
        c, s = np.cos(rot[k : k + step])[:, None], np.sin(rot[k : k + step])[:, None]
        # turned and shifted by broadcasting (einsum's generic loop was most of this function's time)
        sh = shift[k : k + step]
        X0 = c * pts[:, 0] + (-s) * pts[:, 1] + sh[:, 0, None]
        X1 = s * pts[:, 0] + c * pts[:, 1] + sh[:, 1, None]
        r = np.hypot(X0, X1)
        sel = r > r_last
        r_all.append(r[sel])
        a_all.append(np.arctan2(X1[sel], X0[sel]))
    r, a = (np.concatenate(v) if v else np.zeros(0) for v in (r_all, a_all))
    if not len(r):
        return np.empty((0, 2))
    bands = np.floor((r - r_last) / 1e-3).astype(int)
    top = np.full(bands.max() + 1, -np.inf)
    np.maximum.at(top, bands, side * a)
    rb = r_last + (np.arange(len(top)) + 1.0) * 1e-3
    ok = np.isfinite(top)
    ang = side * (top[ok] + (WALL_MARGIN + clearance) / rb[ok])
    # one wall, at the largest angle the tooth reaches beyond the flank (or the flank's own end angle when that is
    # larger): a step along the circle of the flank's last point, then radially out; a shop reads a step, and it
    # keeps the wall on the clear side everywhere
    a_last = float(np.arctan2(last[1], last[0]))
    a_wall = side * max(side * a_last, float(side * ang.max() if side > 0 else side * ang.min()))
    if side * (a_wall - a_last) <= 1e-12:
        return np.empty((0, 2))
    return np.array([[r_last * np.cos(a_wall), r_last * np.sin(a_wall)]])


def _flank_points(cf, clearance: float) -> tuple[np.ndarray, np.ndarray]:
    """The flank's exact points (set back by ``clearance`` along their normals into the rigid tooth: the flank bounds
    space 0 from above, the tooth lies at larger polar angles) and normals, 0.1 um apart at least (the ends are found
    finely), from the tip (inner) outward."""
    fp, fn = np.asarray(cf.points, float), np.asarray(cf.normal, float)
    if clearance:
        e_t = np.stack([-fp[:, 1], fp[:, 0]], -1) / np.hypot(*fp.T)[:, None]
        fp = fp + clearance * np.sign(np.einsum("ij,ij->i", fn, e_t))[:, None] * fn
    keep = np.concatenate([[True], np.hypot(*np.diff(fp, axis=0).T) > 1e-4])
    fp, fn = fp[keep], fn[keep]
    o = np.argsort(np.hypot(*fp.T))
    return fp[o], fn[o]


def conjugate_rigid_gear(drive, z: float | None = None, clearance: float = 0.0) -> tuple[Gear, object]:
    """The rigid gear conjugate to ``drive``'s flexspline at section ``z`` (default: the generator's centre
    section), and the :class:`~wgcad.envelope.space.ConjugateFlank` it was made from.

    ``clearance`` (mm): the flank set back along its normal into the rigid tooth, and the wall beyond it by as
    much: the offset of an envelope is the envelope of the offset tooth, so the pair keeps that normal clearance
    where it was conjugate (designed backlash, docs/models.md 13.3)."""
    rg = drive.rigid
    if not rg.spec.internal:
        raise ValueError("conjugate rigid gears are built for internal deformation (an internal rigid gear)")
    cf = conjugate_flank(drive, z)
    zr = rg.spec.z
    half = pi / zr
    # the flank bounds space 0 (centred on +x) from above; in the tooth frame (rigid tooth centred on +x) it is
    # the tooth's lower flank: turn by -pi/z, then mirror for the upper flank that the half period runs along
    fp, fn = _flank_points(cf, clearance)
    wall = _tip_wall(drive, cf, clearance=clearance, last=fp[-1])
    n_flank = len(fp)
    up = _turn(np.concatenate([fp, wall]), -half) * np.array([1.0, -1.0])
    tan = _turn(np.stack([-fn[:, 1], fn[:, 0]], -1), -half) * np.array([1.0, -1.0])
    is_flank = np.arange(len(up)) < n_flank
    tan_up = np.zeros_like(up)
    tan_up[:n_flank] = tan
    a_up = np.arctan2(up[:, 1], up[:, 0])
    r_f = rg.r_f
    # the tip starts where the flank does: below the flank's first point the tooth's path is bounded by its own
    # corners, not by the envelope, and a radial wall there was crossed (D1: by 0.72 um over 2.3 um of wall), so
    # the tip circle is raised to the first point (D1 involute: from 82.92 to 82.9202 mm)
    r_a = max(rg.r_a, float(np.hypot(*up[0])))
    # above its last point the wall runs radially to the root circle
    tip_pt = r_a * np.array([np.cos(a_up[0]), np.sin(a_up[0])])
    root_pt = r_f * np.array([np.cos(a_up[-1]), np.sin(a_up[-1])])
    hp = [pc.arc((0.0, 0.0), r_a, 0.0, float(a_up[0]))]
    if np.hypot(*(up[0] - tip_pt)) > 1e-12:
        hp.append(pc.line(tip_pt, up[0]))
    # the flank: one tangent-continuous cubic Hermite spline through its exact points with the envelope's tangents (smooth, so
    # exports fit it with few tangent arcs); the wall beyond it: lines
    f_idx = np.flatnonzero(is_flank)
    ends = (f_idx[0], f_idx[-1])
    if not np.all(np.diff(f_idx) == 1):
        raise ValueError("the wall beyond the conjugate flank dips below its last point")
    fpts = up[ends[0] : ends[1] + 1]
    ftan = tan_up[ends[0] : ends[1] + 1]
    ftan = ftan * np.sign(np.einsum("ij,ij->i", ftan, np.gradient(fpts, axis=0)))[:, None]
    hp.append(pc.spline(fpts, ftan))
    for i in range(ends[1], len(up) - 1):
        hp.append(pc.line(up[i], up[i + 1]))
    if np.hypot(*(root_pt - up[-1])) > 1e-12:
        hp.append(pc.line(up[-1], root_pt))
    if a_up[-1] >= half:
        raise ValueError("the conjugate flank reaches past the middle of the space: the rigid teeth would be pointed")
    hp.append(pc.arc((0.0, 0.0), r_f, float(a_up[-1]), half))
    pieces = tuple(pc.merge_arcs(pc.mirror_path(hp) + hp))
    spec = replace(rg.spec, form="conjugate", tip_radius=r_a)
    flank = np.vstack([tip_pt, up]) if np.hypot(*(up[0] - tip_pt)) > 1e-12 else up

    sampler = _ConjugateSampler(
        spec,
        rg.r,
        r_a,
        r_f,
        float(2.0 * r_a * a_up[0]),
        pieces,
        flank,
        a_up[0],
        a_up[-1],
        half,
        zr,
        rg.spec.phase,
        float(np.max(cf.residual_mm)),
        float(cf.sagitta_mm),
    )
    gear = sampler(drive.tol)
    return gear, cf


@dataclass(frozen=True, slots=True)
class _ConjugateSampler:
    """A conjugate rigid gear's outline sampled at a chord tolerance from its exact pieces and flank points (a record,
    so a drive holding the gear pickles): arcs by their sagitta, the flank's exact points thinned (Douglas-Peucker
    to half the tolerance); the pieces keep every point. A finer copy (the audit's finer polygons) samples these
    same pieces: its flank is not enveloped again."""

    spec: object
    r: float
    r_a: float
    r_f: float
    tip_thickness: float
    pieces: tuple
    flank: np.ndarray
    a_first: float
    a_last: float
    half: float
    z: int
    phase: float
    residual_mm: float = 0.0
    sagitta_mm: float = 0.0

    def _flank_at(self, tol: float) -> np.ndarray:
        """The flank's points with the spline's own points between its knots where a knot's chord can lie more than
        a quarter of ``tol`` from the spline (its sagitta bounded by ``max |P''| / 8`` on a segment's unit parameter,
        ``P''`` linear on a cubic). The knots are the envelope's points, about 5e-6 mm of sagitta apart: below a
        tolerance of about 1e-5 mm their chords alone were up to 65 times the tolerance from the exact flank (D1
        double-arc at 5e-8 mm), so the polygon was not the tolerance's. Where no segment needs it (the default
        tolerance) the points are the knots, as before.

        Only below twice the envelope's own sagitta (:attr:`sagitta_mm`): above it the knots' chords are within half
        the tolerance of the envelope. A degenerate flank (a fuzz design whose envelope has a 0.54 mm gap between two
        knots, where the spline loops back across the tooth) is left as its knots there: its looping segment is
        sampled only when a tolerance that fine is asked for."""
        flank = np.asarray(self.flank, float)
        if tol >= 2.0 * self.sagitta_mm:
            return flank
        spl = [p for p in self.pieces if p.kind == "spline" and p.t0 == 0.0]
        for sp in spl:
            c = np.asarray(sp.params).reshape(-1, 4, 2)
            i0 = np.flatnonzero(np.all(flank == c[0, 0], axis=1))
            n = len(c)
            if len(i0) != 1 or i0[0] + n >= len(flank) or not np.array_equal(flank[i0[0] + n], c[-1, 3]):
                continue
            i0 = int(i0[0])
            # |P''(u)| of a cubic Bezier is largest at an end: 6 |c0 - 2 c1 + c2|, 6 |c1 - 2 c2 + c3|
            m2 = 6.0 * np.maximum(
                np.hypot(*(c[:, 0] - 2 * c[:, 1] + c[:, 2]).T), np.hypot(*(c[:, 1] - 2 * c[:, 2] + c[:, 3]).T)
            )
            sub = np.maximum(1, np.ceil(np.sqrt(m2 / (8.0 * 0.25 * tol)))).astype(int)
            if (sub == 1).all():
                continue
            u = np.concatenate([k + np.arange(s) / s for k, s in enumerate(sub)] + [[float(n)]])
            flank = np.concatenate([flank[:i0], sp.point(u), flank[i0 + n + 1 :]])
        return flank

    def __call__(self, tol: float) -> Gear:
        def arc_pts(r, a0, a1):
            n = max(2, int(np.ceil(abs(a1 - a0) * r / np.sqrt(8.0 * r * tol))) + 1)
            a = np.linspace(a0, a1, n)
            return r * np.stack([np.cos(a), np.sin(a)], -1)

        thin = np.asarray(shapely.LineString(self._flank_at(tol)).simplify(0.5 * tol).coords)
        root = arc_pts(self.r_f, self.a_last, self.half)  # from the radial wall's foot (not from the flank)
        half_period = np.concatenate([arc_pts(self.r_a, 0.0, self.a_first)[:-1], thin, root])
        keep = np.concatenate([[True], np.hypot(*np.diff(half_period, axis=0).T) > 1e-9])
        half_period = half_period[keep]
        mirror = half_period[::-1] * np.array([1.0, -1.0])
        period = np.concatenate([mirror, half_period[1:]])
        gamma = 2.0 * pi / self.z
        k = np.arange(self.z)[:, None]
        ang = np.arctan2(period[:-1, 1], period[:-1, 0])[None, :] + k * gamma + self.phase
        rad = np.hypot(period[:-1, 0], period[:-1, 1])[None, :]
        outline = np.stack([rad * np.cos(ang), rad * np.sin(ang)], -1).reshape(-1, 2)
        for arr in (half_period, period, outline):
            arr.setflags(write=False)
        return Gear(
            self.spec,
            self.r,
            self.r_a,
            self.r_f,
            None,
            self.tip_thickness,
            half_period,
            period,
            outline,
            tol,
            self.pieces,
            resample=self,
            envelope_residual_mm=self.residual_mm,
            envelope_sagitta_mm=self.sagitta_mm,
        )
