"""Workshop gear data of one gear: sizes, span measurement over k teeth or dimension between pins, as a table (numpy only)."""

from __future__ import annotations

import numpy as np

from ...profiles.measure import pin_check, span_check

__all__ = ["span_measurement", "pin_dimension", "gear_data", "data_lines"]


def span_measurement(gear) -> dict | None:
    """Span ``W_k`` over ``k`` teeth (external teeth) by the rule of :func:`wgcad.profiles.measure.span_check`, the
    one ``generate``'s report states: the same ``k`` and ``W_k`` in both, with the rule, the method
    and the sensitivity to tooth thickness. None for internal teeth or where no ``k`` puts the jaws on the flanks."""
    sp = span_check(gear)
    if sp is None or sp.get("k") is None:
        return None
    return {
        "k": sp["k"],
        "W_mm": sp["w_k_mm"],
        "contact_radius_mm": 0.5 * sp["contact_diameter_mm"],
        "rule": sp["k_rule"],
        "method": sp["method"],
        "dW_per_thickness": sp["dW_per_thickness"],
    }


def pin_dimension(gear, pin_diameter: float | None = None) -> dict | None:
    """Dimension between (internal) or over (external) two pins by the rule of
    :func:`wgcad.profiles.measure.pin_check` (contact nearest mid-flank with the pin standing out of the teeth
    and clear of the root, gauge pins in 1 um steps), the one ``generate``'s report states, for every tooth form;
    with the sensitivity to tooth thickness. None where no pin fits by that rule."""
    p = pin_check(gear, pin_diameter)
    if not (p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]):
        return None
    internal = gear.spec.internal
    out = {
        "pin_diameter_mm": p["pin_diameter_mm"],
        "M_mm": p["between_pins_mm" if internal else "over_pins_mm"],
        "pin_centre_radius_mm": 0.5 * p["pin_centre_diameter_mm"],
        "kind": "between pins" if internal else "over pins",
        "rule": p["pin_diameter_source"],
        "method": p["method"],
        "dM_per_thickness": p["dM_per_thickness"],
    }
    if "contact_diameter_mm" in p:
        out["contact_radius_mm"] = 0.5 * p["contact_diameter_mm"]
    return out


def gear_data(gear, tol: float) -> dict:
    """The gear-data block of one gear: module, teeth, shift, pressure angle, diameters, measurement, tolerance."""
    sp = gear.spec
    out = {
        "module_mm": sp.module,
        "teeth": sp.z,
        "form": sp.form + (" internal" if sp.internal else " external"),
        # a conjugate gear's flanks are an envelope, not a shifted rack form: no shift to state
        "profile_shift": None if sp.form == "conjugate" else sp.shift,
        "pressure_angle_deg": float(np.rad2deg(sp.alpha)) if sp.form == "involute" else None,
        "tip_diameter_mm": 2.0 * gear.r_a,
        "root_diameter_mm": 2.0 * gear.r_f,
        "pitch_diameter_mm": 2.0 * gear.r,
        "base_diameter_mm": None if gear.r_base is None else 2.0 * gear.r_base,
        "thinning_mm": None if sp.form == "conjugate" else sp.thinning,
        "chord_tolerance_mm": tol,
    }
    if gear.envelope_residual_mm is not None:
        # the flank's distance from the envelope condition (docs/models.md 13.2)
        out["envelope_residual_mm"] = gear.envelope_residual_mm
        out["envelope_chord_sagitta_mm"] = gear.envelope_sagitta_mm
    if sp.form == "double_arc":
        out["double_arc"] = {
            "convex_radius_mm": sp.convex_radius,
            "concave_radius_mm": sp.concave_radius,
            "tangent_angle_deg": float(np.rad2deg(sp.tangent_angle)),
            "tangent_length_mm": sp.tangent_length,
            "datum_diameter_mm": 2.0 * (gear.r + sp.shift * sp.module),
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
        f"profile shift x = {data['profile_shift']:g}"
        if data["profile_shift"] is not None
        else "flanks: conjugate to the flexspline's teeth (envelope of their motion)",
        f"pressure angle = {f(data['pressure_angle_deg'], 2)} deg",
        f"tip diameter = {f(data['tip_diameter_mm'])} mm",
        f"root diameter = {f(data['root_diameter_mm'])} mm",
        f"pitch diameter = {f(data['pitch_diameter_mm'])} mm",
        f"base diameter = {f(data['base_diameter_mm'])} mm",
    ]
    if data.get("envelope_residual_mm") is not None:
        lines.append(
            f"envelope residual = {data['envelope_residual_mm']:.1e} mm (chords within {data['envelope_chord_sagitta_mm']:.1e} mm)"
        )
    if data.get("double_arc"):
        da = data["double_arc"]
        lines.append(
            f"double arc: convex R {da['convex_radius_mm']:.4f}, concave R {da['concave_radius_mm']:.4f} mm, "
            f"common tangent {da['tangent_length_mm']:.4f} mm at {da['tangent_angle_deg']:g} deg"
        )
        lines.append(f"  tangent centred on the datum diameter {da['datum_diameter_mm']:.4f} mm")
    if data["thinning_mm"] is not None:
        lines.append(f"tooth thinning = {data['thinning_mm']:g} mm")
    s = data.get("span")
    if s:
        rate = (
            ""
            if s["dW_per_thickness"] is None
            else f" (changes {s['dW_per_thickness']:.3f} mm per mm of tooth thickness)"
        )
        lines.append(f"span W{s['k']} over {s['k']} teeth = {s['W_mm']:.4f} mm{rate}")
        lines.append(f"  k: {s['rule']}; {s['method']}")
    p = data.get("pins")
    if p:
        rate = (
            (
                " (no tooth-thickness lever: conjugate flanks)"
                if "conjugate" in data["form"]
                else " (its change with tooth thickness is not smooth: not given)"
            )
            if p["dM_per_thickness"] is None
            else f" (changes {p['dM_per_thickness']:.3f} mm per mm of tooth thickness)"
        )
        lines.append(f"dimension {p['kind']} (pin {p['pin_diameter_mm']:.3f} mm) = {p['M_mm']:.4f} mm{rate}")
        lines.append(f"  pin: {p['rule']}; {p['method']}")
    if not s and not p:
        lines.append("span / pins: no caliper or pin position on the flanks")
    lines.append(f"outline tolerance = {data['chord_tolerance_mm'] * 1e3:g} um")
    return lines
