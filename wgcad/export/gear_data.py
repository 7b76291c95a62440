"""Workshop gear data of one gear: sizes, span measurement over k teeth or dimension between pins, as a table (numpy only)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["inv", "inv_inverse", "span_measurement", "pin_dimension", "gear_data", "data_lines"]


def inv(a):
    """Involute function ``tan a - a``."""
    return np.tan(a) - a


def inv_inverse(y: float) -> float:
    """The angle ``a`` in ``[0, pi/2)`` with ``inv(a) = y`` (Newton, to 1e-15)."""
    if y <= 0:
        return 0.0
    a = (3.0 * y) ** (1.0 / 3.0)  # inv(a) ~ a^3 / 3
    a = min(a, 1.5)
    for _ in range(60):
        f = math.tan(a) - a - y
        fp = math.tan(a) ** 2
        step = f / fp
        a = min(max(a - step, 1e-12), 1.5707)
        if abs(step) < 1e-15:
            break
    return a


def _flank_radii(gear) -> tuple[float, float] | None:
    """Radius range covered by the involute pieces of a gear (None if it has none)."""
    rs = []
    for p in gear.pieces:
        if p.kind == "involute":
            rb = p.params[1]
            rs += [rb * math.hypot(1.0, p.t0), rb * math.hypot(1.0, p.t1)]
    return (min(rs), max(rs)) if rs else None


def span_measurement(gear) -> dict | None:
    """Span ``W_k`` over ``k`` teeth of an external involute gear (docs/models.md 2.1).

    ``W_k = r_b (2 psi_b + (k - 1) 2 pi / z)`` with ``psi_b`` the half tooth
    angle on the base circle (``s/(2r) + inv(alpha)``, shift and thinning
    included) -- i.e. ``m cos(a) ((k - 0.5) pi + z inv(a)) + 2 x m sin(a)
    - thinning cos(a)``. ``k`` is the count whose caliper contact radius
    ``sqrt(r_b^2 + (W/2)^2)`` lies nearest the middle of the involute flank;
    None when no ``k`` puts it on the flank.
    """
    sp = gear.spec
    if sp.form != "involute" or sp.internal or gear.r_base is None:
        return None
    rng = _flank_radii(gear)
    if rng is None:
        return None
    r_b = gear.r_base
    psi_b = float(gear.half_angle(r_b))  # half tooth angle on the base circle
    best = None
    target = 0.5 * (rng[0] + rng[1])
    for k in range(1, sp.z):
        w = r_b * (2.0 * psi_b + (k - 1) * 2.0 * math.pi / sp.z)
        rc = math.hypot(r_b, 0.5 * w)
        if rng[0] < rc < rng[1] and (best is None or abs(rc - target) < abs(best[2] - target)):
            best = (k, w, rc)
        if rc > rng[1]:
            break
    if best is None:
        return None
    return {"k": best[0], "W_mm": best[1], "contact_radius_mm": best[2]}


def pin_dimension(gear, pin_diameter: float | None = None) -> dict | None:
    """Dimension between (internal) or over (external) two pins of an involute gear, by the rule the generate report
    states (:func:`wgcad.profiles.measure._pins`: contact nearest mid-flank with the pin standing out of the teeth
    and clear of the root, gauge pins in 1 um steps), docs/models.md 2.1. None for other forms."""
    from ..profiles.measure import _pins

    sp = gear.spec
    if sp.form != "involute" or gear.r_base is None:
        return None
    p = _pins(gear, pin_diameter)
    if not (p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]):
        return None
    M = p["between_pins_mm" if sp.internal else "over_pins_mm"]
    return {
        "pin_diameter_mm": p["pin_diameter_mm"],
        "M_mm": M,
        "pin_centre_radius_mm": 0.5 * p["pin_centre_diameter_mm"],
        "contact_radius_mm": 0.5 * p["contact_diameter_mm"],
        "kind": "between pins" if sp.internal else "over pins",
        "rule": p["pin_diameter_source"],
    }


def gear_data(gear, tol: float) -> dict:
    """The gear-data block of one gear: module, teeth, shift, pressure angle, diameters, measurement, tolerance."""
    sp = gear.spec
    out = {
        "module_mm": sp.module,
        "teeth": sp.z,
        "form": sp.form + (" internal" if sp.internal else " external"),
        "profile_shift": sp.shift,
        "pressure_angle_deg": float(np.rad2deg(sp.alpha)) if sp.form == "involute" else None,
        "tip_diameter_mm": 2.0 * gear.r_a,
        "root_diameter_mm": 2.0 * gear.r_f,
        "pitch_diameter_mm": 2.0 * gear.r,
        "base_diameter_mm": None if gear.r_base is None else 2.0 * gear.r_base,
        "thinning_mm": sp.thinning,
        "chord_tolerance_mm": tol,
    }
    out["span"] = span_measurement(gear)
    out["pins"] = pin_dimension(gear)
    return out


def data_lines(name: str, data: dict) -> list[str]:
    """The gear-data block as text lines (for the DXF GEAR_DATA layer and the drawings)."""
    f = lambda v, nd=4: "-" if v is None else f"{v:.{nd}f}"  # noqa: E731
    lines = [
        f"{name.upper()} GEAR DATA",
        f"module m = {data['module_mm']:g} mm",
        f"teeth z = {data['teeth']} ({data['form']})",
        f"profile shift x = {data['profile_shift']:g}",
        f"pressure angle = {f(data['pressure_angle_deg'], 2)} deg",
        f"tip diameter = {f(data['tip_diameter_mm'])} mm",
        f"root diameter = {f(data['root_diameter_mm'])} mm",
        f"pitch diameter = {f(data['pitch_diameter_mm'])} mm",
        f"base diameter = {f(data['base_diameter_mm'])} mm",
        f"tooth thinning = {data['thinning_mm']:g} mm",
    ]
    s = data.get("span")
    if s:
        lines.append(f"span W{s['k']} over {s['k']} teeth = {s['W_mm']:.4f} mm")
    p = data.get("pins")
    if p:
        lines.append(f"dimension {p['kind']} (pin {p['pin_diameter_mm']:.3f} mm) = {p['M_mm']:.4f} mm")
    if not s and not p:
        lines.append("span / pins: not defined for this tooth form")
    lines.append(f"outline tolerance = {data['chord_tolerance_mm'] * 1e3:g} um")
    return lines
