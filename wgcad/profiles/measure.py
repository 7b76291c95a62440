"""Workshop measurements of one undeformed gear: thickness at a diameter, span over k teeth, dimension over/between pins, smallest concave radius.

Closed forms for involute teeth (in the project's words; ISO 21771 and the
usual gear-measurement texts give the same relations):

* **Thickness at a radius** ``R`` (docs/models.md 2.1): arc thickness
  ``s(R) = 2 R psi(R)`` with ``psi`` the half angle of the tooth; the
  chordal thickness a caliper reads is ``2 R sin psi`` at the chordal height
  ``r_a - R cos psi`` from the tip (internal teeth: ``R cos psi - r_a``).
* **Span over k teeth** (external teeth): a line tangent to the base circle
  is normal to both involutes it crosses, so two parallel jaws touching the
  outer flanks of ``k`` consecutive teeth lie on one such line, and their
  distance is the unrolled base arc between the two flanks:
  ``W_k = r_b (2 psi_b + (k - 1) 2 pi / z)`` with ``psi_b = s/(2r) + inv(alpha)``
  the half angle of a tooth at the base circle. The jaws touch at radius
  ``sqrt(r_b^2 + (W_k/2)^2)``. ``k`` by the usual rule: the one that puts
  the contact on the circle ``r + x m``, ``k = round(z K + 0.5)``,
  ``K = (sec(alpha) sqrt((1 + 2x/z)^2 - cos^2(alpha)) - inv(alpha) - 2 (x/z) tan(alpha)) / pi``;
  when that contact is off the flank (truncated tips, fillets), the ``k``
  whose contact is nearest the middle of the flank.
* **Dimension over pins** (balls give the same): a pin of diameter ``D`` in a
  space touches both flanks where their normals, tangent to the base circle,
  pass through its centre. Walking along such a normal, the polar angle of
  a point at distance ``L`` from the tangent point is ``angle(B) + atan(L/r_b)``,
  which gives the centre's pressure angle ``alpha_M``: external teeth
  ``inv(alpha_M) = psi_b + D/(2 r_b) - pi/z``, internal teeth (the space is
  the involute "tooth", half angle ``sigma_b = e/(2r) + inv(alpha)``)
  ``inv(alpha_M) = sigma_b - D/(2 r_b)``; the centre sits at
  ``R_M = r_b / cos(alpha_M)``. Over two pins (external) ``M = 2 R_M + D``,
  between two pins (internal) ``M = 2 R_M - D``; with an odd tooth count the
  pins are not opposite and ``2 R_M`` becomes ``2 R_M cos(pi / (2z))``. The
  default pin touches the flanks at the middle of the flank.
* **Smallest concave radius** (what a cutter tip or an EDM wire must fit):
  external involute teeth: the root fillet (a sharp corner without one);
  internal teeth also the flank, whose curvature radius
  ``sqrt(R^2 - r_b^2)`` is smallest at the tip, and the root circle.

Cycloidal teeth have closed forms for the thicknesses and the concave radii
(the cycloid's curvature radius ``4 rho (r -+ rho)/(r -+ 2 rho) sin(phi/2)``
vanishes at the pitch point); span and pins are computed numerically on the
sampled outline: the jaw distance as the extent of the flank points across
the axis of symmetry of the ``k`` teeth, the pin centre by bisection on the
space's centre line until its distance to the outline is ``D/2``. The same
numerical routines check the closed forms in the tests.
"""

from __future__ import annotations

from dataclasses import replace
from math import pi

import numpy as np

from ..errors import DesignError
from ..roots import brentq
from . import cycloid as cy
from . import involute as iv
from .gear import Gear, involute_base_angle, make_gear, rotate

__all__ = [
    "flank_zone",
    "thickness_at",
    "span_closed_form",
    "span_numerical",
    "span_k_rule",
    "pins_closed_form",
    "pin_diameter_for_contact",
    "pins_numerical",
    "concave_radii",
    "span_check",
    "pin_check",
    "SENSITIVITY_STEP",
    "workshop_figures",
]

#: change of tooth thickness (mm) for the measurements' sensitivities (central differences): 1 um
SENSITIVITY_STEP = 1e-3


#: how the numerical measurements name the outline they sample
_FORM_OUTLINE = {
    "involute": "involute outline",
    "cycloidal": "cycloidal outline",
    "conjugate": "conjugate outline",
    "double_arc": "double-arc outline",
}


def flank_zone(gear: Gear) -> tuple[float, float]:
    """Radii ``(lo, hi)`` between which the outline is the exact flank (involute or cycloid), mm.

    Below (external) or beyond (internal) it lie the root fillet and the root
    circle; the involute also starts no lower than the base circle.
    """
    sp = gear.spec
    if sp.form == "double_arc":  # convex arc, tangent and concave arc (docs/models.md 2.4)
        return gear.flank_radii
    if sp.form == "cycloidal":
        return tuple(sorted((gear.r_a, gear.r_f)))
    if sp.form == "conjugate":  # the conjugate flank as built (docs/models.md 13): tip circle to its last point
        hp = gear.half_period
        r = np.hypot(hp[:, 0], hp[:, 1])
        lo, hi = min(gear.r_a, gear.r_f), max(gear.r_a, gear.r_f)
        on = r[(r > lo + 1e-9) & (r < hi - 1e-9)]
        return (gear.r_a, float(on.max())) if sp.internal else (float(on.min()), gear.r_a)
    r_b = gear.r_base
    rho = sp.fillet_coef * sp.module
    base = involute_base_angle(sp)
    if sp.internal:
        end = gear.r_f
        if rho > 0:
            _, _, fp, _ = iv.fillet_internal(base, r_b, gear.r_f, rho)
            end = float(np.hypot(*fp))
        return gear.r_a, end
    start = max(gear.r_f, r_b)
    if rho > 0:
        _, _, fp, t_f = iv.fillet_external(base, r_b, gear.r_f, rho)
        start = float(np.hypot(*fp)) if t_f is not None else r_b
    return max(start, r_b), gear.r_a


def thickness_at(gear: Gear, radius: float) -> dict:
    """Arc and chordal tooth thickness at ``radius`` (on the flank), and the chordal height from the tip, mm."""
    R = float(radius)
    psi = float(gear.half_angle(R))
    s = 2.0 * R * psi
    chord = 2.0 * R * np.sin(psi)
    height = (gear.r_a - R * np.cos(psi)) if not gear.spec.internal else (R * np.cos(psi) - gear.r_a)
    return {"diameter_mm": 2.0 * R, "arc_mm": s, "chordal_mm": float(chord), "chordal_height_mm": float(height)}


# ----------------------------------------------------------------------------- span over k teeth
def span_closed_form(gear: Gear, k: int) -> tuple[float, float]:
    """``(W_k, contact radius)`` of external involute teeth, mm (module docstring)."""
    sp = gear.spec
    psi_b = involute_base_angle(sp)
    w = gear.r_base * (2.0 * psi_b + (k - 1) * 2.0 * pi / sp.z)
    return float(w), float(np.hypot(gear.r_base, 0.5 * w))


def span_k_rule(gear: Gear) -> int:
    """The usual number of teeth spanned: contact on the circle ``r + x m`` (module docstring)."""
    sp = gear.spec
    a, f = sp.alpha, sp.shift / sp.z
    K = (np.sqrt((1 + 2 * f) ** 2 - np.cos(a) ** 2) / np.cos(a) - iv.inv(a) - 2 * f * np.tan(a)) / pi
    return int(max(1, min(sp.z - 1, round(float(sp.z * K + 0.5)))))


def span_numerical(gear: Gear, k: int) -> tuple[float, float]:
    """``(W_k, contact radius)`` measured on the sampled outline: extent of the flank points across the axis of symmetry of ``k`` teeth.

    Only points on the flanks count (the jaws reach into the spaces, not
    onto the root lands or fillets), so the result is the distance of two
    parallel lines tangent to the outer flanks when they touch the flanks.
    The teeth are symmetric, so the extent is twice the largest distance of
    the outer (upper) flank of tooth ``k - 1`` from the axis.
    """
    lo, hi = flank_zone(gear)
    half = gear.half_period  # tooth centre to the middle of the space: the upper flank
    R = np.hypot(half[:, 0], half[:, 1])
    on = (R >= lo - 1e-12) & (R <= hi + 1e-12)
    pts = rotate(half[on], (k - 1) * pi / gear.spec.z)  # tooth k-1 seen from the axis of the k teeth
    i = int(np.argmax(pts[:, 1]))
    return float(2.0 * pts[i, 1]), float(R[on][i])


def _span(gear: Gear) -> dict | None:
    if gear.spec.internal:
        return None
    lo, hi = flank_zone(gear)
    closed = gear.spec.form == "involute"
    fn = span_closed_form if closed else span_numerical

    def contact(k):
        return fn(gear, k)

    k0 = span_k_rule(gear) if closed else None
    mid = 0.5 * (lo + hi)
    margin = 0.02 * (hi - lo)  # contact not on the very edge of the flank (tip corner, fillet)
    ok = lambda rc: lo + margin <= rc <= hi - margin  # noqa: E731
    rule = "usual rule (contact on the circle r + x m)"
    if k0 is None or not ok(contact(k0)[1]):
        # the k whose contact is nearest the middle of the flank; the contact moves outward with k
        a, b = 1, max(1, gear.spec.z // 2)
        while a < b:
            c = (a + b) // 2
            a, b = (c + 1, b) if contact(c)[1] < mid else (a, c)
        near = [k for k in (a - 1, a) if k >= 1 and ok(contact(k)[1])]
        rule = "contact nearest the middle of the flank"
        if not near:
            return {"k": None, "note": "no number of teeth puts the jaws on the flanks"}
        k0 = min(near, key=lambda k: abs(contact(k)[1] - mid))
    w, rc = contact(k0)
    return {
        "k": k0,
        "w_k_mm": w,
        "contact_diameter_mm": 2.0 * rc,
        "k_rule": rule,
        "method": "closed form (involute)" if closed else f"numerical (sampled {_FORM_OUTLINE[gear.spec.form]})",
    }


# ----------------------------------------------------------------------------- pins
def _inv_inverse(y: float) -> float:
    """``alpha`` with ``inv(alpha) = y`` (Newton from a cube-root start)."""
    a = (3.0 * y) ** (1.0 / 3.0) if y > 0 else 0.0
    for _ in range(60):
        f = np.tan(a) - a - y
        d = np.tan(a) ** 2
        if d == 0:
            break
        step = f / d
        a -= step
        if abs(step) < 1e-15:
            break
    return float(a)


def pins_closed_form(gear: Gear, d_pin: float) -> dict:
    """Pin centre radius and the dimension over (external) / between (internal) two pins, involute teeth, mm."""
    sp = gear.spec
    base = involute_base_angle(sp)
    r_b = gear.r_base
    y = base - d_pin / (2 * r_b) if sp.internal else base + d_pin / (2 * r_b) - pi / sp.z
    a_m = _inv_inverse(y)
    R_m = r_b / np.cos(a_m)
    span = 2 * R_m * (1.0 if sp.z % 2 == 0 else np.cos(pi / (2 * sp.z)))
    return {"centre_radius_mm": float(R_m), "dimension_mm": float(span - d_pin if sp.internal else span + d_pin)}


def pin_diameter_for_contact(gear: Gear, radius: float) -> float:
    """Pin diameter that touches involute flanks at ``radius`` (module docstring), mm."""
    sp = gear.spec
    r_b = gear.r_base
    base = involute_base_angle(sp)
    t = np.sqrt((radius / r_b) ** 2 - 1.0)
    if sp.internal:
        return float(2 * r_b * (t - np.tan(t - base)))
    return float(2 * r_b * (np.tan(pi / sp.z - base + t) - t))


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab, ap = b - a, p - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    u = np.clip(np.where(L2 > 0, np.einsum("ij,ij->i", ap, ab) / np.where(L2 > 0, L2, 1.0), 0.0), 0.0, 1.0)
    d = ap - u[:, None] * ab
    return np.hypot(d[:, 0], d[:, 1])


def _space_outline(gear: Gear) -> np.ndarray:
    """Teeth 0 and 1 of the sampled outline around the space centred on ``pi / z``, ``(n, 2)``."""
    gamma = 2.0 * pi / gear.spec.z
    return np.concatenate([gear.period, rotate(gear.period, gamma)[1:]])


def _dist_to_outline(poly: np.ndarray, p: np.ndarray) -> float:
    return float(_seg_dist(np.broadcast_to(p, (len(poly) - 1, 2)), poly[:-1], poly[1:]).min())


def _dists(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Distance of each point ``(n, 2)`` to the polyline ``poly``, ``(n,)``."""
    a, b = poly[:-1][None], poly[1:][None]
    ab, ap = b - a, pts[:, None, :] - a
    L2 = np.einsum("ijk,ijk->ij", np.broadcast_to(ab, ap.shape), np.broadcast_to(ab, ap.shape))
    u = np.clip(np.einsum("ijk,ijk->ij", ap, np.broadcast_to(ab, ap.shape)) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
    d = ap - u[..., None] * ab
    return np.hypot(d[..., 0], d[..., 1]).min(axis=1)


def pins_numerical(gear: Gear, d_pin: float) -> dict:
    """Pin centre found geometrically on the sampled outline: on the space's centre line where its distance to the outline is ``D/2``."""
    sp = gear.spec
    poly = _space_outline(gear)
    u = np.array([np.cos(pi / sp.z), np.sin(pi / sp.z)])
    f = lambda R: _dist_to_outline(poly, R * u) - 0.5 * d_pin  # noqa: E731
    # external: the space widens outward, the pin sinks until it touches; internal: it widens inward
    lo, hi = sorted((gear.r_a, gear.r_f))
    a, b = lo - 0.5 * d_pin, hi + 1.5 * d_pin
    grid = np.linspace(a, b, 120)
    vals = _dists(poly, grid[:, None] * u[None, :]) - 0.5 * d_pin
    # the resting position: coming from outside the teeth (outward for external teeth, from the
    # centre for internal ones), where the pin's clearance to the outline changes sign
    s = np.sign(vals)
    if sp.internal:
        idx = np.nonzero((s[:-1] > 0) & (s[1:] <= 0))[0]
    else:
        idx = np.nonzero((s[:-1] <= 0) & (s[1:] > 0))[0]
    if idx.size == 0:
        raise ArithmeticError("the pin does not touch both flanks")
    i = idx[0] if sp.internal else idx[-1]
    R_m = brentq(f, grid[i], grid[i + 1], xtol=1e-13)
    span = 2 * R_m * (1.0 if sp.z % 2 == 0 else np.cos(pi / (2 * sp.z)))
    return {"centre_radius_mm": float(R_m), "dimension_mm": float(span - d_pin if sp.internal else span + d_pin)}


def _pins(gear: Gear, d_pin: float | None) -> dict:
    sp = gear.spec
    lo, hi = flank_zone(gear)
    mid = 0.5 * (lo + hi)
    closed = sp.form == "involute"
    chosen = d_pin is not None
    measure = pins_closed_form if closed else pins_numerical

    # clear of the root by more than the outline's own error: a pin that rests on the root land touches no flank,
    # and its dimension does not change with the tooth thickness it is there to check (D1 cycloidal's flexspline
    # pin sat on the root circle: 79.96 - 0.36 = 79.6 mm = r_f, and read the same for 100 um of thinning)
    clear_by = 2.0 * gear.tol

    def fits(d):
        # the pin must stand out of the teeth (for the caliper) and stay clear of the root
        R_m = measure(gear, d)["centre_radius_mm"]
        if sp.internal:
            return R_m - 0.5 * d < gear.r_a, R_m + 0.5 * d < gear.r_f - clear_by
        return R_m + 0.5 * d > gear.r_a, R_m - 0.5 * d > gear.r_f + clear_by

    if d_pin is None:
        u = np.array([np.cos(pi / sp.z), np.sin(pi / sp.z)])
        poly = None if closed else _space_outline(gear)

        def pin_at(rc):  # the pin touching the flanks at rc (involute), or centred at rc (numerical)
            return pin_diameter_for_contact(gear, rc) if closed else 2.0 * _dist_to_outline(poly, rc * u)

        # contact as near mid-flank as the pin allows: first the middle, then outward/inward from it
        cands = mid + (hi - lo) * np.array([0.0, *np.ravel([[-f, f] for f in np.linspace(0.05, 0.45, 9)])])
        d_pin = round(pin_at(mid), 3)
        for rc in cands:
            d = round(pin_at(rc), 3)  # gauge pins come in 1 um steps
            if d > 0 and all(fits(d)):
                d_pin = d
                break
    res = measure(gear, d_pin)
    R_m = res["centre_radius_mm"]
    proud, clear = fits(d_pin)
    out = {
        "pin_diameter_mm": d_pin,
        "pin_diameter_source": "design"
        if chosen
        else "contact nearest mid-flank with the pin standing out of the teeth, 1 um steps",
        "between_pins_mm" if sp.internal else "over_pins_mm": res["dimension_mm"],
        "pin_centre_diameter_mm": 2.0 * R_m,
        "pin_stands_out_of_the_teeth": bool(proud),
        "pin_clear_of_the_root": bool(clear),
        "method": "closed form (involute)" if closed else f"numerical (sampled {_FORM_OUTLINE[gear.spec.form]})",
    }
    if closed:
        # contact radius: where the flank normal through the centre touches the flank
        t_c = np.tan(np.arccos(gear.r_base / R_m)) + (d_pin if sp.internal else -d_pin) / (2 * gear.r_base)
        out["contact_diameter_mm"] = float(2.0 * gear.r_base * np.sqrt(1.0 + t_c * t_c))
    return out


# ----------------------------------------------------------------------------- concave radii
def concave_radii(gear: Gear) -> dict:
    """Smallest curvature radius of each concave piece of the outline (material side), mm; closed forms."""
    sp = gear.spec
    out = {}
    if sp.form == "conjugate":
        # the radial wall above the conjugate flank meets the root circle in a corner (docs/models.md 13)
        return {"root_corner": 0.0, "root_circle": gear.r_f} if sp.internal else {"root_corner": 0.0}
    if sp.form == "double_arc":  # the concave arc and the fillet curve into the space (docs/models.md 2.4)
        out = {"concave_flank": sp.concave_radius, "root_fillet": sp.fillet_coef * sp.module}
        if sp.internal:
            out["root_circle"] = gear.r_f
        return out
    if sp.form == "involute":
        rho = sp.fillet_coef * sp.module
        out["root_fillet"] = rho  # 0: the flank meets the root in a sharp corner
        if sp.internal:
            out["flank_at_tip"] = float(np.sqrt(gear.r_a**2 - gear.r_base**2))
            out["root_circle"] = gear.r_f
    else:
        # the concave flank is the dedendum: hypocycloid (external) / epicycloid (internal);
        # its curvature radius 4 rho (r -+ rho)/(r -+ 2 rho) sin(phi/2) is 0 at the pitch point
        r, rho = gear.r, gear.rho
        epi = sp.internal
        c = 4 * rho * (r + rho) / (r + 2 * rho) if epi else 4 * rho * (r - rho) / (r - 2 * rho)
        phi_f = float(cy.roll_angle_at_radius(r, rho, gear.r_f, epi))
        out["dedendum_cycloid_at_pitch_point"] = 0.0
        out["dedendum_cycloid_at_root"] = float(c * np.sin(phi_f / 2))
        if sp.internal:
            out["root_circle"] = gear.r_f
    return out


def workshop_figures(gear: Gear, measure_diameter: float | None = None, pin_diameter: float | None = None) -> dict:
    """Everything a workshop measures on one gear (module docstring), lengths mm."""
    lo, hi = flank_zone(gear)
    mid_r = 0.5 * (gear.r_a + gear.r_f)
    out = {"flank_from_diameter_mm": 2 * lo, "flank_to_diameter_mm": 2 * hi}
    if lo <= mid_r <= hi:
        out["mid_depth"] = thickness_at(gear, mid_r)
    else:  # mid-depth in the fillet: the middle of the flank instead
        out["mid_depth"] = {
            **thickness_at(gear, 0.5 * (lo + hi)),
            "note": "mid-depth lies on the fillet: middle of the flank",
        }
    if measure_diameter is not None:
        out["at_chosen_diameter"] = thickness_at(gear, 0.5 * measure_diameter)
    out["span"] = span_check(gear)
    out["pins"] = pin_check(gear, pin_diameter)
    radii = concave_radii(gear)
    out["concave_radii_mm"] = radii
    out["smallest_concave_radius_mm"] = min(radii.values())
    out["thickness_method"] = (
        "the conjugate flank as built"
        if gear.spec.form == "conjugate"
        else ("exact (the circle met by the arcs and the tangent)" if gear.spec.form == "double_arc" else "closed form")
    )
    return out


def _thicker(gear: Gear, ds: float) -> Gear:
    """The same gear with every tooth ``ds`` thicker at the pitch circle (``thinning`` less by ``ds``)."""
    return make_gear(replace(gear.spec, thinning=gear.spec.thinning - ds), gear.tol)


def span_check(gear: Gear) -> dict | None:
    """Span over ``k`` teeth by the one rule both ``generate``'s report and the part set's gear data state
    (module docstring), with its sensitivity to tooth thickness: ``dW_per_thickness`` is the change of ``W_k``
    per mm of tooth thickness at the pitch circle (central differences of +-:data:`SENSITIVITY_STEP` at the
    same ``k``; the closed form gives ``cos(alpha)`` for involute teeth), so a shop can turn a thickness
    tolerance into a span tolerance. None for internal teeth (no caliper spans them)."""
    out = _span(gear)
    if out is None or out.get("k") is None:
        return out
    fn = span_closed_form if gear.spec.form == "involute" else span_numerical
    return {**out, "dW_per_thickness": _per_thickness(gear, lambda g: fn(g, out["k"])[0], out["w_k_mm"])}


def pin_check(gear: Gear, pin_diameter: float | None = None) -> dict:
    """Dimension over (external) or between (internal) two pins by the one rule of every command (module
    docstring), with ``dM_per_thickness``: the change of the dimension per mm of tooth thickness at the pitch
    circle (central differences of +-:data:`SENSITIVITY_STEP`, the same pin; None where it is not smooth,
    :func:`_per_thickness`)."""
    out = _pins(gear, pin_diameter)
    measure = pins_closed_form if gear.spec.form == "involute" else pins_numerical
    key = "between_pins_mm" if gear.spec.internal else "over_pins_mm"
    d = out["pin_diameter_mm"]
    return {**out, "dM_per_thickness": _per_thickness(gear, lambda g: measure(g, d)["dimension_mm"], out[key])}


def _per_thickness(gear: Gear, figure, at: float) -> float | None:
    if gear.spec.form == "conjugate":  # its flanks are the envelope, not a thinned rack form: no thickness lever
        return None
    return _per_thickness_form(gear, figure, at)


def _per_thickness_form(gear: Gear, figure, at: float) -> float | None:
    """d figure / d tooth thickness (mm/mm), or None where it is not a derivative one can use.

    Central differences of +-:data:`SENSITIVITY_STEP` (one-sided where a
    tooth that much thicker or thinner cannot be built: no thinning left, or
    a tooth at the minimum tip thickness), checked
    against the same at 4 times the step: where the two differ by more than
    5 % the figure is not smooth in the thickness (a pin whose seat jumps
    between features of a cycloidal space) and no sensitivity is given.
    """

    def side(ds):
        try:
            return figure(_thicker(gear, ds))
        except DesignError:  # no thinning left (the space closes) or a pointed tooth (at the minimum tip): not built
            return None

    def diff(h):
        hi, lo = side(h), side(-h)
        if hi is not None and lo is not None:
            return (hi - lo) / (2.0 * h)
        if hi is not None:
            return (hi - at) / h
        if lo is not None:
            return (at - lo) / h
        return None

    d1, d4 = diff(SENSITIVITY_STEP), diff(4.0 * SENSITIVITY_STEP)
    if d1 is None or d4 is None:
        return None
    return d1 if abs(d1 - d4) <= 0.05 * max(abs(d1), abs(d4)) else None
