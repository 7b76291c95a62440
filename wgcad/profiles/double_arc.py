"""Double-circular-arc ("common tangent") teeth: a convex arc toward the tip, a straight common tangent, a concave
arc toward the root (docs/models.md 2.4).

The tooth form of modern cup strain-wave gears: the convex addendum arc of
radius ``rho_a`` and the concave dedendum arc of radius ``rho_f`` are joined
by their common tangent, a straight segment of length ``l`` inclined by the
angle ``delta`` against the tooth's radial centre line. Built here in the
gear's plane (tooth frame, tooth centred on +x): the tangent's midpoint lies
on the datum circle ``r_p = r + x m`` (``x`` the design's shift, which moves
the datum radially), where the tooth is half the datum's pitch thick less
the thinning; the arcs leave the tangent's ends tangentially and run to the
tip circle and toward the root circle, which a fillet of ``fillet_coef m``
joins (tangent to both). Internal teeth (pointing inward) are built the same
way with the radial direction reversed. Every piece is an arc or a line:
exact, and written as such to DXF and STEP.
"""

from __future__ import annotations

from math import pi

import numpy as np

from ..errors import DesignError
from ..roots import brentq
from . import pieces as pc
from .sampling import arc_points

__all__ = ["double_arc_half_period", "DEFAULTS"]

#: the form's parameters when the design leaves them out (multiples of the module, degrees)
DEFAULTS = {
    "convex_radius_coef": 1.0,
    "concave_radius_coef": 1.2,
    "tangent_angle_deg": 20.0,
    "tangent_length_coef": 0.2,
}


def _e(a: float) -> np.ndarray:
    return np.array([np.cos(a), np.sin(a)])


def _travel(center, radius: float, start: np.ndarray, direction: np.ndarray) -> tuple[float, float]:
    """Polar angle of ``start`` about ``center`` and the sense (+1/-1) in which the arc leaves it along ``direction``."""
    a = float(np.arctan2(start[1] - center[1], start[0] - center[0]))
    tangent = np.array([-np.sin(a), np.cos(a)])  # d/da of center + radius e(a), over radius
    return a, (1.0 if float(tangent @ direction) > 0 else -1.0)


def _first_crossing(center, radius: float, a0: float, sense: float, R: float) -> float | None:
    """The first angle from ``a0`` (in ``sense``, within half a turn) where the arc reaches the circle ``|p| = R``."""

    def f(a):
        p = center + radius * _e(a)
        return float(p @ p) - R * R

    grid = a0 + sense * np.linspace(0.0, pi, 721)
    vals = np.array([f(a) for a in grid])
    s0 = np.sign(vals[0])
    if s0 == 0:
        return float(a0)
    hit = np.nonzero(np.sign(vals[1:]) != s0)[0]
    if hit.size == 0:
        return None
    i = int(hit[0])
    return float(brentq(f, grid[i], grid[i + 1], xtol=1e-15))  # to 1e-15 + 4 eps |a|, as scipy's with rtol = 4 eps


def _arc_to_circle(center, radius: float, start, direction, R: float, key: str, which: str, circle: str, fix: str):
    """The arc leaving ``start`` along ``direction`` about ``center``: its start angle, sense and the angle where it
    first reaches the circle ``|p| = R`` (DesignError on ``key`` when it turns back first)."""
    a0, sense = _travel(center, radius, start, direction)
    a1 = _first_crossing(center, radius, a0, sense, R)
    if a1 is None:
        raise DesignError(
            key,
            f"the {which} arc (radius {radius:.4f} mm) turns back before it reaches the {circle} circle {R:.4f} mm: "
            f"a larger {which} radius or {fix}",
        )
    return a0, sense, a1


def _sweep(a0: float, a1: float, sense: float) -> float:
    """``a1`` expressed so that going from ``a0`` to it runs in ``sense`` (less than a full turn)."""
    d = (a1 - a0) % (2 * pi)
    return a0 + (d if sense > 0 else d - 2 * pi)


def double_arc_half_period(sp, r: float, r_a: float, r_f: float, tol: float, tip_field: str):
    """Upper half of one pitch of a double-arc tooth, tooth frame, increasing angle (docs/models.md 2.4).

    Returns ``(points, tip_thickness, None, pieces, flank_radii)``: the polyline from the tooth centre on the tip
    circle to the middle of the space on the root circle (every vertex on its piece), the tip's chordal...arc
    thickness, no base circle, the exact pieces in the same order and direction, and the radii between which
    the outline is flank (arcs and tangent; the rest is tip, fillet and root).
    """
    f = "tooth"
    g = sp.field
    m = sp.module
    sg = -1.0 if sp.internal else 1.0  # +1: the tooth points outward
    rho_a, rho_f = sp.convex_radius, sp.concave_radius
    delta, length = sp.tangent_angle, sp.tangent_length
    r_p = r + sp.shift * m
    half = (pi * r_p / sp.z - sp.thinning) / (2.0 * r_p)
    if not half > 0:
        raise DesignError(f"{g}.thinning", "leaves no tooth at the datum circle")
    p0 = r_p * _e(half)
    er, et = _e(half), _e(half + pi / 2)
    t = sg * np.cos(delta) * er - np.sin(delta) * et  # along the flank toward the tip
    n = sg * np.sin(delta) * er + np.cos(delta) * et  # the flank's normal, into the space
    pa, pf = p0 + 0.5 * length * t, p0 - 0.5 * length * t
    beyond = (lambda R: R >= r_a) if not sp.internal else (lambda R: R <= r_a)
    if beyond(float(np.hypot(*pa))):
        raise DesignError(
            f"{f}.tangent_length_coef", "the common tangent reaches the tip circle: a shorter tangent or a higher tip"
        )
    # convex arc: from the tangent's tip end to the tip circle
    ca = pa - rho_a * n
    a_pa, s_a, a_tip = _arc_to_circle(ca, rho_a, pa, t, r_a, f"{f}.convex_radius_coef", "convex", "tip", "a lower tip")
    tip_pt = ca + rho_a * _e(a_tip)
    psi_tip = float(np.arctan2(tip_pt[1], tip_pt[0]))
    if psi_tip <= 0:
        raise DesignError(tip_field, "pointed teeth: the convex arcs of both flanks meet below the tip circle")
    # concave arc: from the tangent's root end toward the root circle
    cf = pf + rho_f * n
    a_pf, s_f, a_root = _arc_to_circle(
        cf, rho_f, pf, -t, r_f, f"{f}.concave_radius_coef", "concave", "root", "a shallower root"
    )
    gamma2 = pi / sp.z
    rho = sp.fillet_coef * m
    hp = [pc.arc((0.0, 0.0), r_a, 0.0, psi_tip), pc.arc(ca, rho_a, _sweep(a_pa, a_tip, s_a), a_pa)]
    if length > 0:
        hp.append(pc.line(pa, pf))
    if rho > 0:
        a_end, fil = _fillet(sp, cf, rho_f, a_pf, s_f, a_root, r_f, rho)
        hp.append(pc.arc(cf, rho_f, a_pf, a_end))
        hp.append(fil)
        root0 = float(np.arctan2(fil.end[1], fil.end[0]))
        flank_end = cf + rho_f * _e(a_end)
    else:
        hp.append(pc.arc(cf, rho_f, a_pf, _sweep(a_pf, a_root, s_f)))
        flank_end = cf + rho_f * _e(a_root)
        root0 = float(np.arctan2(flank_end[1], flank_end[0]))
    margin = 0.05 * m / r_f
    if root0 > gamma2 - margin:
        raise DesignError(
            f"{g}.fillet_coef" if rho > 0 else f"{f}.concave_radius_coef",
            f"the space closes before the root circle {r_f:.4f} mm: a smaller concave radius or fillet, or thinner teeth",
        )
    hp.append(pc.arc((0.0, 0.0), r_f, root0, gamma2))
    pts = [arc_points((0.0, 0.0), r_a, 0.0, psi_tip, tol)]
    for p in hp[1:]:
        if p.kind == "line":
            pts.append(np.array([p.end]))
        else:
            c, R = p.center, p.radius
            pts.append(arc_points(c, R, p.t0, p.t1, tol)[1:])
    out = np.concatenate(pts)
    radii = (float(np.hypot(*flank_end)), r_a)
    flank = (min(radii), max(radii))
    return out, 2.0 * r_a * psi_tip, None, hp, flank


def _fillet(sp, cf, rho_f: float, a_pf: float, s_f: float, a_root: float, r_f: float, rho: float):
    """The fillet of radius ``rho`` tangent inside the concave arc and to the root circle; returns the concave arc's
    end angle and the fillet piece (from the concave arc to the root circle)."""
    g = sp.field
    if rho >= rho_f:
        raise DesignError(
            f"{g}.fillet_coef", f"the fillet ({rho:.4f} mm) must be smaller than the concave arc ({rho_f:.4f} mm)"
        )
    R1 = r_f - rho if sp.internal else r_f + rho  # the fillet's centre lies in the space, rho off the root circle
    R2 = rho_f - rho
    d = float(np.hypot(*cf))
    a = (R1 * R1 - R2 * R2 + d * d) / (2 * d)
    h2 = R1 * R1 - a * a
    if h2 < 0:
        raise DesignError(
            f"{g}.fillet_coef", f"a fillet of {rho:.4f} mm cannot touch both the concave arc and the root"
        )
    u = cf / d
    v = np.array([-u[1], u[0]])
    span = (_sweep(a_pf, a_root, s_f) - a_pf) * s_f  # how far the concave arc runs to the root circle
    for c in (a * u + np.sqrt(h2) * v, a * u - np.sqrt(h2) * v):
        a_t = float(np.arctan2(c[1] - cf[1], c[0] - cf[0]))
        run = ((a_t - a_pf) * s_f) % (2 * pi)
        if 0 < run <= span + 1e-12:
            q = c * (r_f / np.hypot(*c))
            tp = cf + rho_f * _e(a_t)
            b0 = float(np.arctan2(tp[1] - c[1], tp[0] - c[0]))
            b1 = float(np.arctan2(q[1] - c[1], q[0] - c[0]))
            b1 = b0 + (b1 - b0 + pi) % (2 * pi) - pi
            return a_pf + s_f * run, pc.arc(c, rho, b0, b1)
    raise DesignError(f"{g}.fillet_coef", f"a fillet of {rho:.4f} mm does not fit between the concave arc and the root")


def half_angle_at(gear, radius) -> np.ndarray:
    """Half the tooth's angular thickness at ``radius`` (flank zone), rad: the circle ``|p| = radius`` met exactly by
    the flank's convex arc, common tangent or concave arc (the pieces of the upper flank, tooth frame)."""
    radius = np.asarray(radius, dtype=float)
    flank = [p for p in gear.pieces if _on_upper_flank(p, gear)]
    out = np.full(radius.shape, np.nan)
    for idx, R in np.ndenumerate(radius):
        for p in flank:
            a = _meet(p, float(R))
            if a is not None:
                out[idx] = a
                break
    return out


def _on_upper_flank(p, gear) -> bool:
    """Whether piece ``p`` of the pitch is part of the upper flank: off the axis, above it, both ends in the flank zone
    (the tip and root arcs are centred on the axis, the fillet runs out of the zone to the root)."""
    if p.kind == "arc" and np.allclose(p.center, 0.0, atol=1e-12):
        return False
    lo, hi = gear.flank_radii
    ends = [float(np.hypot(*q)) for q in (p.start, p.end)]
    mid = np.asarray(p.point(np.array([0.5 * (p.t0 + p.t1)]))).reshape(-1, 2)[0]
    return float(mid[1]) > 0 and all(lo - 1e-9 <= R <= hi + 1e-9 for R in ends)


def _meet(p, R: float) -> float | None:
    """Polar angle where piece ``p`` (arc or line) crosses the circle ``|x| = R``, or None."""
    if p.kind == "line":
        a0, d = p.start, p.end - p.start
        A, B, C = float(d @ d), 2.0 * float(a0 @ d), float(a0 @ a0) - R * R
        disc = B * B - 4 * A * C
        if disc < 0:
            return None
        for s in ((-B + np.sqrt(disc)) / (2 * A), (-B - np.sqrt(disc)) / (2 * A)):
            if -1e-12 <= s <= 1 + 1e-12:
                q = a0 + s * d
                return float(np.arctan2(q[1], q[0]))
        return None
    c, rho = p.center, p.radius
    dc = float(np.hypot(*c))
    cosv = (R * R - dc * dc - rho * rho) / (2 * rho * dc)
    if abs(cosv) > 1:
        return None
    phi_c = float(np.arctan2(c[1], c[0]))
    lo, hi = sorted((p.t0, p.t1))
    for sgn in (1.0, -1.0):
        a = phi_c + sgn * np.arccos(cosv)
        a = lo + (a - lo) % (2 * pi)
        if a <= hi + 1e-12:
            q = c + rho * _e(a)
            return float(np.arctan2(q[1], q[0]))
    return None
