"""Whole-gear geometry: radii, derived-geometry checks and the toothed outline of one gear (docs/models.md 2.1, 2.2)."""

from __future__ import annotations

from dataclasses import dataclass, field
from math import pi

import numpy as np

from .. import constants
from ..errors import DesignError
from ..plane import signed_area
from . import cycloid as cy
from . import involute as iv
from . import pieces as pc
from .double_arc import double_arc_half_period, half_angle_at
from .sampling import arc_points, polar, sample_curve

__all__ = ["ToothSpec", "Gear", "make_gear", "rotate", "largest_fillet_coef"]


def rotate(points: np.ndarray, angle: float) -> np.ndarray:
    """Rotate points ``(..., 2)`` counter-clockwise by ``angle`` about the origin."""
    c, s = np.cos(angle), np.sin(angle)
    pts = np.asarray(points, dtype=float)
    return np.stack([c * pts[..., 0] - s * pts[..., 1], s * pts[..., 0] + c * pts[..., 1]], axis=-1)


@dataclass(frozen=True, slots=True)
class ToothSpec:
    """Everything that fixes one gear's teeth. Lengths mm, angles rad.

    ``field`` is the design-file table the values came from (``flexspline``
    or ``rigid``); error messages name ``field.key``.
    """

    z: int
    module: float
    internal: bool
    form: str = "involute"  # "involute" | "cycloidal" | "double_arc" | "conjugate" (built by wgcad.envelope)
    alpha: float = np.deg2rad(20.0)
    addendum_coef: float = 1.0
    clearance_coef: float = 0.25
    shift: float = 0.0
    tip_radius: float | None = None
    root_radius: float | None = None
    thinning: float = 0.0
    fillet_coef: float = 0.25
    field: str = "gear"
    #: where the *tooth* centre sits at the reference position (rad): 0 for the
    #: flexspline, half a pitch for the rigid gear (its space is on +x)
    phase: float = 0.0
    #: double-arc teeth (docs/models.md 2.4): convex and concave arc radii (mm), the common tangent's
    #: inclination (rad) and length (mm)
    convex_radius: float = 0.0
    concave_radius: float = 0.0
    tangent_angle: float = 0.0
    tangent_length: float = 0.0


@dataclass(frozen=True, slots=True)
class Gear:
    """One gear's teeth, undeformed. Read-only arrays; lengths mm, angles rad.

    Attributes
    ----------
    spec : ToothSpec
    r, r_a, r_f : float
        Pitch, tip and root radii (for an internal gear the tip is the
        innermost radius, docs/models.md 2.1).
    r_base : float or None
        Base radius (involute only).
    half_period : (n, 2) float
        The toothed boundary from the tooth centre (angle 0, on the tip) to
        the middle of the next space (angle pi/z, on the root), in
        increasing polar angle; tooth frame (tooth centred on +x).
    period : (p, 2) float
        One pitch of the boundary, -pi/z .. pi/z, tooth frame.
    outline : (N, 2) float
        The whole toothed boundary, counter-clockwise, closed implicitly,
        turned by ``spec.phase``.
    pieces : tuple of :class:`~wgcad.profiles.pieces.Piece`
        The exact curves of one pitch, -pi/z .. pi/z in the tooth frame, in
        the order and direction of :attr:`period`; each piece ends where the
        next begins, and every vertex of :attr:`period` lies on one of them.
    """

    spec: ToothSpec
    r: float
    r_a: float
    r_f: float
    r_base: float | None
    tip_thickness: float
    half_period: np.ndarray = field(repr=False)
    period: np.ndarray = field(repr=False)
    outline: np.ndarray = field(repr=False)
    tol: float = constants.CHORD_TOL
    pieces: tuple = field(default=(), repr=False)
    #: radii (lo, hi) between which the outline is flank, where the form has no closed form for them (double arc)
    flank_radii: tuple | None = None
    #: ``resample(tol)``: this gear's exact pieces sampled at another chord tolerance, where the pieces are not the
    #: spec's alone (a conjugate gear's flank comes from an envelope: :meth:`sampled_at`)
    resample: object = field(default=None, repr=False, compare=False)
    #: a conjugate gear's envelope residual, mm: the largest distance of the flank's exact points from the envelope
    #: condition (Newton's), and the largest gap between the chords joining them and the envelope (None: not an
    #: envelope)
    envelope_residual_mm: float | None = None
    envelope_sagitta_mm: float | None = None

    def sampled_at(self, tol: float) -> Gear | None:
        """The same exact curves sampled at chord tolerance ``tol``; None where the spec rebuilds them
        (:func:`make_gear` at ``tol``)."""
        return None if self.resample is None else self.resample(tol)

    def outline_pieces(self) -> list:
        """The exact pieces of the whole :attr:`outline` (``z`` pitches turned by ``k 2 pi/z + phase``), in its order."""
        return [p.rotated(k * self.pitch_angle + self.spec.phase) for k in range(self.spec.z) for p in self.pieces]

    @property
    def pitch_angle(self) -> float:
        """Angular pitch ``2 pi / z``, rad."""
        return 2.0 * pi / self.spec.z

    @property
    def rho(self) -> float:
        """Rolling-circle radius of cycloidal teeth, ``m/4`` (docs/models.md 2.2)."""
        return self.spec.module / 4.0

    def half_angle(self, radius) -> np.ndarray:
        """Half the tooth's angular thickness at ``radius`` (flank zone, no fillet), rad."""
        sp = self.spec
        radius = np.asarray(radius, dtype=float)
        if sp.form == "double_arc":  # exact: where the circle of each radius meets the flank's arcs and tangent
            return half_angle_at(self, radius)
        if sp.form == "conjugate":  # the flank as built (docs/models.md 13): its polyline, angle against radius
            hp = self.half_period
            r = np.hypot(hp[:, 0], hp[:, 1])
            lo, hi = min(self.r_a, self.r_f), max(self.r_a, self.r_f)
            on = (r > lo + 1e-9) & (r < hi - 1e-9)
            rf, af = r[on], np.arctan2(hp[on, 1], hp[on, 0])
            o = np.argsort(rf)
            return np.interp(radius, rf[o], af[o])
        if sp.form == "involute":
            psi_b = involute_base_angle(sp)
            h = iv.half_angle_at(psi_b, self.r_base, radius)
            return (pi / sp.z - h) if sp.internal else h
        return cy.exact_half_angle(self.r, self.rho, radius, sp.internal) - _thin_angle(sp, self.r)

    def tooth_thickness(self, radius) -> np.ndarray:
        """Arc tooth thickness at ``radius`` (flank zone), mm: ``s(R)`` of docs/models.md 2.1."""
        radius = np.asarray(radius, dtype=float)
        return 2.0 * radius * self.half_angle(radius)

    def space_width(self, radius) -> np.ndarray:
        """Arc space width at ``radius``, mm: ``2 pi R / z - s(R)``."""
        radius = np.asarray(radius, dtype=float)
        return 2.0 * pi * radius / self.spec.z - self.tooth_thickness(radius)

    def tooth_polygon(self, depth: float | None = None) -> np.ndarray:
        """One tooth as a closed polygon ``(n, 2)``, tooth frame, counter-clockwise.

        :attr:`period` (space centre to space centre across the tooth), closed
        radially through the gear body ``depth`` beyond the root circle
        (default half a module): a chord would cut the root arcs of an
        internal gear.
        """
        depth = 0.5 * self.spec.module if depth is None else depth
        # beyond the period's own deepest point too: a conjugate space can run deeper than the nominal root circle
        # (a rigid gear's envelope with its shift left out: 2.3 mm on D1 conjugate), and a closure inside the period
        # made the polygon cross itself (an internal error in the audit, found by the fuzzer)
        r = np.hypot(self.period[:, 0], self.period[:, 1])
        r_body = max(self.r_f, float(r.max())) + depth if self.spec.internal else min(self.r_f, float(r.min())) - depth
        a = pi / self.spec.z
        ends = polar(r_body, np.array([a, -a]))
        poly = np.concatenate([self.period, ends])
        if self.spec.internal:
            poly = poly[::-1]  # the period runs clockwise around an internal gear's tooth
        return np.ascontiguousarray(poly)

    def area(self) -> float:
        """Area enclosed by :attr:`outline` (shoelace), mm^2."""
        return signed_area(self.outline)


def _thin_angle(sp: ToothSpec, r: float) -> float:
    # thinning reduces the arc tooth thickness at the pitch circle: each flank
    # turns by thinning / (2 r) toward the tooth centre (docs/models.md 2.1)
    return sp.thinning / (2.0 * r)


def involute_base_angle(sp: ToothSpec) -> float:
    """``s/(2r) + inv(alpha)`` (external tooth) or ``e/(2r) + inv(alpha)`` (internal space), docs/models.md 2.1."""
    r = sp.module * sp.z / 2.0
    nominal = sp.module * (pi / 2.0 + 2.0 * sp.shift * np.tan(sp.alpha))
    width = nominal + sp.thinning if sp.internal else nominal - sp.thinning
    return width / (2.0 * r) + float(iv.inv(sp.alpha))


def tooth_radii(sp: ToothSpec) -> tuple[float, float]:
    m, r = sp.module, sp.module * sp.z / 2.0
    if sp.form in ("involute", "double_arc"):  # both from the shifted datum, h_a* and c* (docs/models.md 2.4)
        if sp.internal:
            r_a = r + m * (sp.shift - sp.addendum_coef)
            r_f = r + m * (sp.shift + sp.addendum_coef + sp.clearance_coef)
        else:
            r_a = r + m * (sp.addendum_coef + sp.shift)
            r_f = r - m * (sp.addendum_coef + sp.clearance_coef - sp.shift)
    else:  # cycloidal, docs/models.md 2.2 (rho = m/4)
        rho = m / 4.0
        if sp.internal:
            r_a, r_f = r - 2 * rho + sp.clearance_coef * m, r + 2 * rho
        else:
            r_a, r_f = r + 2 * rho - sp.clearance_coef * m, r - 2 * rho
    if sp.tip_radius is not None:
        r_a = float(sp.tip_radius)
    if sp.root_radius is not None:
        r_f = float(sp.root_radius)
    return float(r_a), float(r_f)


def make_gear(sp: ToothSpec, tol: float = constants.CHORD_TOL) -> Gear:
    """Build a gear's outline and check its derived geometry.

    Raises
    ------
    DesignError
        Tip inside root, pointed teeth, undercut, involute below the base
        circle, a root fillet that does not fit; the message names the field
        of ``sp.field`` to change.
    """
    f = sp.field
    r = sp.module * sp.z / 2.0
    r_a, r_f = tooth_radii(sp)
    if sp.internal and not r_a < r_f:
        raise DesignError(
            f"{f}.tip_radius", f"tip radius {r_a:.4f} mm must be inside the root radius {r_f:.4f} mm for internal teeth"
        )
    if not sp.internal and not r_a > r_f:
        raise DesignError(
            f"{f}.tip_radius",
            f"tip radius {r_a:.4f} mm must be outside the root radius {r_f:.4f} mm for external teeth",
        )
    if r_f <= 0 or r_a <= 0:
        raise DesignError(f"{f}.root_radius", f"radii must be positive (tip {r_a:.4f} mm, root {r_f:.4f} mm)")
    # the field that sets the tip and how to blunt it: cycloidal teeth have no shift, c* truncates them (docs/models.md 2.2)
    if sp.form in ("involute", "double_arc"):
        tip_field = f"{f}.tip_radius" if sp.tip_radius is not None else f"{f}.shift"
        fix = "lower the shift or truncate the tip"
    elif sp.tip_radius is not None:
        tip_field, fix = f"{f}.tip_radius", "truncate the tip: tip_radius nearer the pitch circle"
    else:
        tip_field, fix = "tooth.clearance_coef", "truncate the tip: larger tooth.clearance_coef (or a tip_radius)"
    flank_radii = None
    if sp.form == "involute":
        half, tip_thk, r_base, hp = _involute_half_period(sp, r, r_a, r_f, tol, tip_field)
    elif sp.form == "double_arc":
        half, tip_thk, r_base, hp, flank_radii = double_arc_half_period(sp, r, r_a, r_f, tol, tip_field)
    else:
        half, tip_thk, r_base, hp = _cycloid_half_period(sp, r, r_a, r_f, tol, tip_field, fix)
    s_min = constants.MIN_TIP_THICKNESS_COEF * sp.module
    if tip_thk < s_min:
        raise DesignError(
            tip_field,
            f"pointed teeth: tip thickness {tip_thk:.4f} mm is below the minimum {s_min:.4f} mm "
            f"({constants.MIN_TIP_THICKNESS_COEF} m); {fix}",
        )
    half = _thin(half, constants.MIN_VERTEX_SPACING)
    hp = [p for p in hp if p.length() > constants.DUPLICATE_TOL]
    pieces = tuple(pc.merge_arcs(pc.mirror_path(hp) + hp))
    mirror = half[::-1] * np.array([1.0, -1.0])
    period = np.concatenate([mirror, half[1:]])
    gamma = 2.0 * pi / sp.z
    k = np.arange(sp.z)[:, None]
    ang = np.arctan2(period[:-1, 1], period[:-1, 0])[None, :] + k * gamma + sp.phase
    rad = np.hypot(period[:-1, 0], period[:-1, 1])[None, :]
    outline = polar(np.broadcast_to(rad, ang.shape), ang).reshape(-1, 2)
    for arr in (half, period, outline):
        arr.setflags(write=False)
    return Gear(sp, r, r_a, r_f, r_base, float(tip_thk), half, period, outline, tol, pieces, flank_radii)


def _fillet_fits(sp: ToothSpec, rho: float) -> bool:
    """Whether a root fillet of radius ``rho`` fits (closed form, no sampling)."""
    r = sp.module * sp.z / 2.0
    r_a, r_f = tooth_radii(sp)
    r_b = r * np.cos(sp.alpha)
    base = involute_base_angle(sp)
    gamma2 = pi / sp.z
    margin = constants.ROOT_SPACE_MIN_COEF * sp.module / r_f
    if sp.internal:
        if r_f - rho <= r_b:
            return False
        _, ang_c, fp, _ = iv.fillet_internal(base, r_b, r_f, rho)
        return ang_c >= margin - 1e-12 * gamma2 and float(np.hypot(*fp)) > r_a
    _, ang_c, fp, _ = iv.fillet_external(base, r_b, r_f, rho)
    return ang_c <= gamma2 * (1 - 1e-12) - margin and float(np.hypot(*fp)) < r_a


def largest_fillet_coef(sp: ToothSpec) -> float:
    """Largest ``fillet_coef`` (fillet radius / m) whose fillet fits the root space (bisection to 1e-6)."""
    lo, hi = 0.0, 2.0
    if not _fillet_fits(sp, 1e-9 * sp.module):
        return 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _fillet_fits(sp, mid * sp.module) else (lo, mid)
        if hi - lo < 1e-7:
            break
    return lo


def _no_fit(sp: ToothSpec, rho: float, why: str) -> DesignError:
    best = largest_fillet_coef(sp)
    return DesignError(
        f"{sp.field}.fillet_coef",
        f"root fillet radius {rho:.4f} mm {why}; the largest that fits is fillet_coef = {np.floor(best * 1e4) / 1e4:.4f}",
    )


def _thin(pts: np.ndarray, spacing: float) -> np.ndarray:
    """Drop vertices closer than ``spacing`` to the last kept one; both end points are kept.

    Every kept vertex is an original one (it stays on the exact curve); the
    chord that replaces a dropped vertex is shorter than ``spacing`` plus the
    neighbouring chord, so its deviation from the curve stays far below the
    chord tolerance (constants.MIN_VERTEX_SPACING).
    """
    keep = [0]
    for i in range(1, len(pts) - 1):
        if np.hypot(*(pts[i] - pts[keep[-1]])) >= spacing:
            keep.append(i)
    last = len(pts) - 1
    while len(keep) > 1 and np.hypot(*(pts[last] - pts[keep[-1]])) < spacing:
        keep.pop()
    if last > 0:
        keep.append(last)
    return np.ascontiguousarray(pts[keep])


def _join(*pieces: np.ndarray) -> np.ndarray:
    return np.concatenate([np.atleast_2d(p) for p in pieces if len(p)])


def _arc_piece(center, radius, p0, p1) -> pc.Piece:
    """The short arc of ``radius`` about ``center`` from ``p0`` to ``p1`` (as :func:`_short_arc`)."""
    a0 = np.arctan2(p0[1] - center[1], p0[0] - center[0])
    a1 = np.arctan2(p1[1] - center[1], p1[0] - center[0])
    return pc.arc(center, radius, a0, a0 + (a1 - a0 + pi) % (2 * pi) - pi)


def _short_arc(center, p0, p1, tol) -> np.ndarray:
    a0 = np.arctan2(p0[1] - center[1], p0[0] - center[0])
    a1 = np.arctan2(p1[1] - center[1], p1[0] - center[0])
    d = (a1 - a0 + pi) % (2 * pi) - pi
    rad = float(np.hypot(p0[0] - center[0], p0[1] - center[1]))
    pts = arc_points(center, rad, a0, a0 + d, tol)
    pts[0], pts[-1] = p0, p1
    return pts


def _involute_half_period(sp: ToothSpec, r, r_a, r_f, tol, tip_field):
    """Upper half of one pitch, tooth frame, increasing angle (docs/models.md 2.1)."""
    f = sp.field
    gamma2 = pi / sp.z
    r_b = r * np.cos(sp.alpha)
    rho = sp.fillet_coef * sp.module
    base = involute_base_angle(sp)
    if not sp.internal:
        # undercut by a standard rack: x < h_a* - z sin^2(alpha)/2
        x_min = sp.addendum_coef - sp.z * np.sin(sp.alpha) ** 2 / 2.0
        if sp.shift < x_min - 1e-12:
            raise DesignError(
                f"{f}.shift",
                f"undercut: shift {sp.shift:g} is below the minimum {x_min:.4f} = h_a* - z sin^2(alpha)/2 for rack generation",
            )
        psi_a = float(iv.half_angle_at(base, r_b, r_a)) if r_a >= r_b else base
        tip_thk = 2.0 * r_a * psi_a
        if r_a <= r_b:
            raise DesignError(
                tip_field, f"tip radius {r_a:.4f} mm is inside the base circle {r_b:.4f} mm: no involute flank"
            )
        t_a = np.sqrt((r_a / r_b) ** 2 - 1.0)
        flank = lambda t: iv.involute_flank(base, r_b, t)  # noqa: E731
        tip = arc_points((0.0, 0.0), r_a, 0.0, psi_a, tol)
        hp = [pc.arc((0.0, 0.0), r_a, 0.0, psi_a)]
        if rho > 0:
            center, ang_c, fp, t_f = iv.fillet_external(base, r_b, r_f, rho)
            fp_r = float(np.hypot(*fp))
            if fp_r >= r_a:
                raise _no_fit(sp, rho, f"reaches the tip (tangent at {fp_r:.4f} mm >= tip {r_a:.4f} mm)")
            if ang_c > gamma2 * (1 - 1e-12) - constants.ROOT_SPACE_MIN_COEF * sp.module / r_f:
                raise _no_fit(sp, rho, f"does not fit the space at the root circle ({r_f:.4f} mm)")
            if t_f is not None:
                fl = sample_curve(flank, t_a, t_f, tol)
                hp.append(pc.involute(base, r_b, t_a, t_f))
            else:
                fl = _join(sample_curve(flank, t_a, 0.0, tol), fp[None, :])
                hp += [pc.involute(base, r_b, t_a, 0.0), pc.line(fl[-2], fp)]
            root0 = ang_c
            fil = _short_arc(center, fl[-1], polar(r_f, ang_c), tol)
            hp.append(_arc_piece(center, rho, fl[-1], fil[-1]))
            pieces = [tip, fl[1:], fil[1:]]
        else:
            if r_f >= r_b:
                t_r = np.sqrt((r_f / r_b) ** 2 - 1.0)
                fl = sample_curve(flank, t_a, t_r, tol)
                hp.append(pc.involute(base, r_b, t_a, t_r))
            else:
                fl = _join(sample_curve(flank, t_a, 0.0, tol), polar(r_f, base)[None, :])
                hp += [pc.involute(base, r_b, t_a, 0.0), pc.line(fl[-2], fl[-1])]
            root0 = float(np.arctan2(fl[-1, 1], fl[-1, 0]))
            if root0 >= gamma2:
                raise DesignError(
                    f"{f}.root_radius", "teeth overlap at the root circle: the space closes before the root"
                )
            pieces = [tip, fl[1:]]
        root = arc_points((0.0, 0.0), r_f, root0, gamma2, tol)
        hp.append(pc.arc((0.0, 0.0), r_f, root0, gamma2))
        return _join(*pieces, root[1:]), tip_thk, float(r_b), hp
    # internal gear: work on the space (centred on angle 0 in its own frame),
    # then map to the tooth frame by a -> gamma/2 - a
    if r_a <= r_b:
        raise DesignError(
            tip_field,
            f"tip radius {r_a:.4f} mm of the internal teeth is inside the base circle {r_b:.4f} mm: no involute flank",
        )
    sig_a = float(iv.half_angle_at(base, r_b, r_a))
    tip_thk = 2.0 * r_a * (gamma2 - sig_a)
    t_a = np.sqrt((r_a / r_b) ** 2 - 1.0)
    flank = lambda t: iv.involute_flank(base, r_b, t)  # noqa: E731
    if rho > 0:
        if r_f - rho <= r_b:
            raise _no_fit(sp, rho, f"reaches below the base circle {r_b:.4f} mm")
        center, ang_c, fp, t_f = iv.fillet_internal(base, r_b, r_f, rho)
        if float(np.hypot(*fp)) <= r_a:
            raise _no_fit(sp, rho, "reaches the tip circle")
        if ang_c < constants.ROOT_SPACE_MIN_COEF * sp.module / r_f - 1e-12 * gamma2:
            raise _no_fit(sp, rho, f"does not fit the space at the root circle ({r_f:.4f} mm)")
        fl = sample_curve(flank, t_a, t_f, tol)
        fil = _short_arc(center, fl[-1], polar(r_f, ang_c), tol)
        space_side = _join(fl, fil[1:])
        sp_pieces = [pc.involute(base, r_b, t_a, t_f), _arc_piece(center, rho, fl[-1], fil[-1])]
        root0 = ang_c
    else:
        t_r = np.sqrt((r_f / r_b) ** 2 - 1.0)
        space_side = sample_curve(flank, t_a, t_r, tol)
        sp_pieces = [pc.involute(base, r_b, t_a, t_r)]
        root0 = float(np.arctan2(space_side[-1, 1], space_side[-1, 0]))
        if root0 <= 0:
            raise DesignError(f"{f}.root_radius", "the space closes before the root circle")
    root = arc_points((0.0, 0.0), r_f, root0, 0.0, tol)
    space_side = _join(space_side, root[1:])  # space frame: from tip to space centre
    sp_pieces.append(pc.arc((0.0, 0.0), r_f, root0, 0.0))
    tooth_frame = rotate(space_side * np.array([1.0, -1.0]), gamma2)
    tip = arc_points((0.0, 0.0), r_a, 0.0, gamma2 - sig_a, tol)
    hp = [pc.arc((0.0, 0.0), r_a, 0.0, gamma2 - sig_a)] + [p.mirrored().rotated(gamma2) for p in sp_pieces]
    return _join(tip, tooth_frame[1:]), tip_thk, float(r_b), hp


def _cycloid_half_period(sp: ToothSpec, r, r_a, r_f, tol, tip_field, fix):
    """Upper half of one pitch of an exact cycloidal tooth, tooth frame (docs/models.md 2.2)."""
    f = sp.field
    if sp.shift != 0.0:
        raise DesignError(f"{f}.shift", "must be 0 for cycloidal teeth (docs/models.md 2.2 has no profile shift)")
    gamma2 = pi / sp.z
    rho = sp.module / 4.0
    q = pi * rho / r - _thin_angle(sp, r)  # pitch point of the upper flank
    add_epi = not sp.internal  # external teeth: epicycloid addendum
    lo, hi = (r - 2 * rho, r + 2 * rho)
    # the addendum flank runs from the pitch circle to the tip, the dedendum flank from it to the
    # root: a tip or root across the pitch circle has no flank to end on (docs/models.md 2.2)
    reach = {"tip": (r, hi) if add_epi else (lo, r), "root": (lo, r) if add_epi else (r, hi)}
    for name, where, val in (("tip", tip_field, r_a), ("root", f"{f}.root_radius", r_f)):
        a, b = reach[name]
        if not a - 1e-12 <= val <= b + 1e-12:
            raise DesignError(
                where,
                f"{name} radius {val:.4f} mm must lie in [{a:.4f}, {b:.4f}] mm, between the pitch "
                "circle and the cycloid's reach (pitch radius +- m/2)",
            )
    curve_a = cy.epicycloid if add_epi else cy.hypocycloid
    curve_d = cy.hypocycloid if add_epi else cy.epicycloid
    phi_a = float(cy.roll_angle_at_radius(r, rho, r_a, add_epi))
    phi_f = float(cy.roll_angle_at_radius(r, rho, r_f, not add_epi))
    # addendum flank leans toward the tooth centre: mirror, then turn to the pitch point
    add = lambda p: rotate(curve_a(r, rho, p) * np.array([1.0, -1.0]), q)  # noqa: E731
    ded = lambda p: rotate(curve_d(r, rho, p), q)  # noqa: E731
    a_pts = sample_curve(add, phi_a, 0.0, tol)
    d_pts = sample_curve(ded, 0.0, phi_f, tol)
    psi_a = float(np.arctan2(a_pts[0, 1], a_pts[0, 0]))
    if psi_a <= 0:
        raise DesignError(tip_field, f"pointed teeth: the flanks meet below the tip radius; {fix}")
    tip_thk = 2.0 * r_a * psi_a
    tip = arc_points((0.0, 0.0), r_a, 0.0, psi_a, tol)
    root0 = float(np.arctan2(d_pts[-1, 1], d_pts[-1, 0]))
    if root0 > gamma2 * (1 + 1e-9):
        raise DesignError(f"{f}.thinning", "negative thinning closes the space at the root")
    root = arc_points((0.0, 0.0), r_f, root0, gamma2, tol)
    hp = [
        pc.arc((0.0, 0.0), r_a, 0.0, psi_a),
        pc.cycloid("epicycloid" if add_epi else "hypocycloid", r, rho, phi_a, 0.0, rot=q, flip=-1.0),
        pc.cycloid("hypocycloid" if add_epi else "epicycloid", r, rho, 0.0, phi_f, rot=q),
        pc.arc((0.0, 0.0), r_f, root0, gamma2),
    ]
    return _join(tip, a_pts[1:], d_pts[1:], root[1:]), tip_thk, None, hp
