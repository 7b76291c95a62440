"""Derived figures of a drive as data (units in the key names) and as a readable summary."""

from __future__ import annotations

from math import pi

import numpy as np

from .. import __version__
from ..errors import DesignError
from ..kinematics import gear_ratios
from ..placement import place_points, place_points_first_order, tooth_angles
from ..profiles import cycloid as cy
from ..profiles import measure

__all__ = ["gear_figures", "workshop", "mesh_figures", "drive_report", "format_summary"]


def _r(x, nd=6):
    return None if x is None else round(float(x), nd)


def cycloid_rack_error(gear, n: int = 2001) -> float:
    """Largest difference, mm, between the rack-approximation and the exact cycloidal tooth thickness (docs/models.md 2.2)."""
    r, rho, internal = gear.r, gear.rho, gear.spec.internal
    lo, hi = sorted((gear.r_a, gear.r_f))
    R = np.linspace(lo, hi, n)
    exact = cy.exact_half_angle(r, rho, R, internal)
    rack = cy.rack_half_angle(r, rho, R, internal)
    return float(np.max(np.abs(2.0 * R * (exact - rack))))


def _rounded(x, nd=6):
    """Floats of nested dicts rounded for the report."""
    if isinstance(x, dict):
        return {k: _rounded(v, nd) for k, v in x.items()}
    if isinstance(x, float):
        return _r(x, nd)
    return x


def workshop(gear, gs=None) -> dict:
    """What a workshop measures on one gear (:mod:`wgcad.profiles.measure`), checked against the design's own choices.

    Raises
    ------
    DesignError
        ``measure_diameter`` off the flanks, or a ``pin_diameter`` that does
        not stand out of the teeth or touches the root.
    """
    which = gear.spec.field
    dm = None if gs is None else gs.measure_diameter
    dp = None if gs is None else gs.pin_diameter
    if dm is not None:
        lo, hi = measure.flank_zone(gear)
        if not 2 * lo <= dm <= 2 * hi:
            raise DesignError(
                f"{which}.measure_diameter",
                f"{dm:g} mm is off the flanks, which run from {2 * lo:.4f} to {2 * hi:.4f} mm in diameter",
            )
    try:
        w = measure.workshop_figures(gear, dm, dp)
    except ArithmeticError:
        if dp is None:
            raise
        raise DesignError(
            f"{which}.pin_diameter", f"a pin of {dp:g} mm does not touch both flanks of a space"
        ) from None
    p = w["pins"]
    if dp is not None and not (p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]):
        why = "does not stand out of the teeth" if not p["pin_stands_out_of_the_teeth"] else "touches the root"
        raise DesignError(
            f"{which}.pin_diameter", f"a pin of {dp:g} mm {why}; choose another (or omit it for the default)"
        )
    return _rounded(w)


def gear_figures(gear, rim_radius: float, gs=None) -> dict:
    """Radii, thicknesses and the workshop's measurements of one gear (docs/models.md 2); ``gs`` its design table."""
    sp = gear.spec
    within = bool(min(gear.r_a, gear.r_f) <= gear.r <= max(gear.r_a, gear.r_f))
    # involute and cycloidal flanks extend beyond the teeth (virtual figures); a double arc's end at its arcs
    extends = within or sp.form != "double_arc"
    out = {
        "teeth": sp.z,
        "internal_teeth": sp.internal,
        "form": sp.form,
        "shift": sp.shift,
        "pitch_radius_mm": _r(gear.r),
        "tip_radius_mm": _r(gear.r_a),
        "root_radius_mm": _r(gear.r_f),
        "base_radius_mm": _r(gear.r_base),
        "rim_radius_mm": _r(rim_radius),
        # with large profile shifts the pitch circle lies outside the teeth: the
        # figures there are those of the extended involutes ("virtual")
        "pitch_circle_within_teeth": within,
        # virtual when the pitch circle lies outside the teeth (then one of them is negative): kept as
        # design figures of the extended flanks, not shown as measurements
        "tooth_thickness_pitch_mm": _r(gear.tooth_thickness(gear.r)) if extends else None,
        "space_width_pitch_mm": _r(gear.space_width(gear.r)) if extends else None,
        # said next to the values: a consumer of the JSON must not take them for measurements
        "pitch_figures": "measured"
        if within
        else (
            "virtual (extended flanks; the pitch circle lies outside the teeth)"
            if extends
            else "none (the pitch circle lies outside the teeth, and double-arc flanks do not extend)"
        ),
        "tip_thickness_mm": _r(gear.tip_thickness),
        "fillet_radius_mm": _r(sp.fillet_coef * sp.module) if sp.form in ("involute", "double_arc") else None,
        "outline_vertices": int(len(gear.outline)),
        "outline_area_mm2": _r(gear.area(), 4),
    }
    if sp.form == "cycloidal":
        out["cycloid_rack_vs_exact_um"] = _r(1e3 * cycloid_rack_error(gear), 4)
    if gear.envelope_residual_mm is not None:
        # a conjugate flank: its exact points' distance from the envelope condition, and its chords' (13.2)
        out["envelope_residual_mm"] = float(f"{gear.envelope_residual_mm:.3g}")
        out["envelope_chord_sagitta_mm"] = float(f"{gear.envelope_sagitta_mm:.3g}")
    out["workshop"] = workshop(gear, gs)
    return out


def mesh_figures(drive, law=None) -> dict:
    """Depth of engagement and radial clearances at the major and minor axes (docs/models.md 2.1, 3).

    Teeth on the major axis (phi = 0) and the minor axis (phi = pi/n_w) are
    carried radially by ``w`` alone (``v = theta = 0`` there by symmetry), so
    these are exact radial figures of the placed teeth.
    """
    law = drive.law if law is None else law
    f, b = drive.flex, drive.rigid
    n_w = drive.design.drive.waves
    w_major = float(law.state(np.array([0.0])).w[0])
    w_minor = float(law.state(np.array([pi / n_w])).w[0])
    sgn = -1.0 if drive.external else 1.0  # +: flexspline teeth point outward
    return {
        "w_major_mm": _r(w_major),
        "w_minor_mm": _r(w_minor),
        "depth_of_engagement_mm": _r(sgn * ((f.r_a + w_major) - b.r_a)),
        "clearance_flex_tip_major_um": _r(1e3 * sgn * (b.r_f - (f.r_a + w_major)), 3),
        "clearance_rigid_tip_major_um": _r(1e3 * sgn * (b.r_a - (f.r_f + w_major)), 3),
        "tip_gap_minor_um": _r(1e3 * sgn * (b.r_a - (f.r_a + w_minor)), 3),
    }


def placement_check(drive) -> dict:
    """Largest distance between exact and first-order tooth placement over all teeth at phi_h = 0, um (docs/models.md 3.1)."""
    d = drive.design.drive
    _, phi = tooth_angles(d.z_flex, d.z_rigid, 0.0)
    exact = place_points(drive.flex.period, drive.law, phi, drive.r_m)
    first = place_points_first_order(drive.flex.period, drive.law, phi, drive.r_m)
    centre = place_points_first_order(drive.flex.period, drive.law, phi, drive.r_m, centreline=True)

    def worst(a, b):
        return float(np.max(np.hypot(*(a - b).transpose(2, 0, 1))))

    return {
        "exact_vs_first_order_um": _r(1e3 * worst(exact, first), 4),
        "exact_vs_centreline_form_um": _r(1e3 * worst(exact, centre), 4),
        "w0_squared_over_r_m_um": _r(1e3 * drive.law.w0**2 / drive.r_m, 4),
    }


def drive_report(drive) -> dict:
    """Everything ``wgcad generate`` reports, as JSON-ready data."""
    des = drive.design
    d = des.drive
    ratios = gear_ratios(d.z_flex, d.z_rigid)
    rep = {
        "wgcad_version": __version__,
        "design": d.name,
        "source": des.source,
        "chord_tol_um": _r(drive.tol * 1e3, 6),
        "outline_error": (
            "undeformed gears (DXF layers FLEXSPLINE, RIGID and the STL solids): a symmetric band, "
            "within chord_tol_um of the exact curves on either side; deformed-state DXFs: chords "
            "through points of the exact curves, so within chord_tol_um on the concave side only"
        ),
        "drive": {
            "module_mm": d.module,
            "z_flex": d.z_flex,
            "z_rigid": d.z_rigid,
            "waves": d.waves,
            "deformation": d.deformation,
            "fixed": d.fixed,
            "face_width_mm": d.face_width,
            "ratio_rigid_fixed": _r(ratios["u_hg"], 9),
            "ratio_flexspline_fixed": _r(ratios["u_hb"], 9),
            "law": des.generator.law,
            "beta_deg": des.generator.beta_deg,
            "w0_mm": _r(des.w0),
            "neutral_radius_mm": _r(drive.r_m),
        },
        "flexspline": gear_figures(drive.flex, drive.flex_rim_radius, des.flexspline),
        "rigid": gear_figures(drive.rigid, drive.rigid_rim_radius, des.rigid),
        "mesh": mesh_figures(drive),
        "placement": placement_check(drive),
    }
    if drive.coned:
        secs = {}
        for z in (0.0, d.face_width):
            secs[f"z_{z:g}_mm"] = mesh_figures(drive, drive.law_at(z))
        rep["mesh_at_face_ends"] = secs
    return rep


def format_summary(rep: dict) -> str:
    """A readable multi-line summary of :func:`drive_report`."""
    d = rep["drive"]
    lines = [
        f"{rep['design']}  ({rep['source']})",
        f"  module {d['module_mm']} mm, z_flex {d['z_flex']}, z_rigid {d['z_rigid']}, {d['waves']} waves, "
        f"{d['deformation']} deformation, {d['law']} law, W0 {d['w0_mm']} mm",
        f"  ratio u_hg (rigid fixed) {d['ratio_rigid_fixed']:g}, u_hb (flexspline fixed) {d['ratio_flexspline_fixed']:g}",
        "",
        f"  {'':38s}{'flexspline':>20s}{'rigid':>20s}",
    ]
    lines += _gear_rows(rep["flexspline"], rep["rigid"])
    lines += ["", "  workshop measurements (undeformed gears)"]
    lines += _workshop_rows(rep["flexspline"], rep["rigid"])
    lines += [""] + _mesh_lines(rep)
    return "\n".join(lines)


def _fmt(v) -> str:
    return "-" if v is None else f"{v:.4f}" if isinstance(v, float) else str(v)


def _row(label: str, fv, bv) -> str:
    """One line of the two-column table: the flexspline's figure, the rigid gear's."""
    return f"  {label:38s}{_fmt(fv):>20s}{_fmt(bv):>20s}"


def _gear_rows(f: dict, b: dict) -> list[str]:
    """The gears' radii, tip thickness, outline size, and the pitch-circle figures where they mean something."""
    lines = []
    for label, key in (
        ("pitch radius, mm", "pitch_radius_mm"),
        ("tip radius, mm", "tip_radius_mm"),
        ("root radius, mm", "root_radius_mm"),
        ("base radius, mm", "base_radius_mm"),
        ("rim radius, mm", "rim_radius_mm"),
        ("tip thickness, mm", "tip_thickness_mm"),
        ("outline vertices", "outline_vertices"),
    ):
        lines.append(_row(label, f.get(key), b.get(key)))
    if "cycloid_rack_vs_exact_um" in f:
        lines.append(
            _row("rack vs exact cycloid, um", f.get("cycloid_rack_vs_exact_um"), b.get("cycloid_rack_vs_exact_um"))
        )
    if "envelope_residual_mm" in b:
        lines.append(f"  {'conjugate flank: envelope residual, mm':38s}{'-':>20s}{b['envelope_residual_mm']:>20.1e}")
        lines.append(f"  {'  chords off the envelope, mm':38s}{'-':>20s}{b['envelope_chord_sagitta_mm']:>20.1e}")
    # the pitch-circle figures only where the pitch circle crosses the teeth: outside them they are
    # figures of the extended flanks (one of them negative), not something to measure
    if f["pitch_circle_within_teeth"] or b["pitch_circle_within_teeth"]:
        for label, key in (
            ("tooth thickness @pitch, mm", "tooth_thickness_pitch_mm"),
            ("space width @pitch, mm", "space_width_pitch_mm"),
        ):
            lines.append(_row(label, *(g[key] if g["pitch_circle_within_teeth"] else None for g in (f, b))))
    return lines


def _span(w) -> str:
    sp = w["span"]
    if sp is None:
        return "internal teeth"
    return "none fits" if sp.get("k") is None else f"{sp['w_k_mm']:.4f} (k={sp['k']})"


def _span_rate(w) -> str:
    sp = w["span"]
    if sp is None or sp.get("k") is None or sp["dW_per_thickness"] is None:
        return "-"
    return f"{sp['dW_per_thickness']:.3f}"


def _pin_fits(w) -> bool:
    p = w["pins"]
    return p["pin_stands_out_of_the_teeth"] and p["pin_clear_of_the_root"]


def _pin(w, key) -> str:
    # a pin that does not stand out of the teeth or rests on the root checks no tooth thickness: not given
    if not _pin_fits(w):
        return "none fits"
    p = w["pins"]
    if key == "dimension":
        return f"{p.get('over_pins_mm', p.get('between_pins_mm')):.4f}"
    if key == "diameter":
        return f"{p['pin_diameter_mm']:.3f}"
    return "not smooth" if p["dM_per_thickness"] is None else f"{p['dM_per_thickness']:.3f}"


def _workshop_rows(f: dict, b: dict) -> list[str]:
    """What a shop measures on the undeformed gears: thicknesses, span, pins, concave radii; with the methods."""
    wf, wb = f["workshop"], b["workshop"]
    lines = [
        _row(
            "flanks between diameters, mm",
            f"{wf['flank_from_diameter_mm']:.3f}-{wf['flank_to_diameter_mm']:.3f}",
            f"{wb['flank_from_diameter_mm']:.3f}-{wb['flank_to_diameter_mm']:.3f}",
        ),
        _row("mid-depth diameter, mm", wf["mid_depth"]["diameter_mm"], wb["mid_depth"]["diameter_mm"]),
        _row("  thickness there: arc, mm", wf["mid_depth"]["arc_mm"], wb["mid_depth"]["arc_mm"]),
        _row("  chordal thickness, mm", wf["mid_depth"]["chordal_mm"], wb["mid_depth"]["chordal_mm"]),
        _row(
            "  chordal height from the tip, mm",
            wf["mid_depth"]["chordal_height_mm"],
            wb["mid_depth"]["chordal_height_mm"],
        ),
    ]
    if "at_chosen_diameter" in wf or "at_chosen_diameter" in wb:
        cf, cb = wf.get("at_chosen_diameter", {}), wb.get("at_chosen_diameter", {})
        lines += [
            _row("chosen diameter, mm", cf.get("diameter_mm"), cb.get("diameter_mm")),
            _row("  thickness there: arc, mm", cf.get("arc_mm"), cb.get("arc_mm")),
            _row("  chordal thickness, mm", cf.get("chordal_mm"), cb.get("chordal_mm")),
            _row("  chordal height from the tip, mm", cf.get("chordal_height_mm"), cb.get("chordal_height_mm")),
        ]
    lines += [
        _row("span W_k over k teeth, mm", _span(wf), _span(wb)),
        _row("  change per mm of tooth thickness", _span_rate(wf), _span_rate(wb)),
        _row("pin (ball) diameter, mm", _pin(wf, "diameter"), _pin(wb, "diameter")),
        _row("dimension over / between pins, mm", _pin(wf, "dimension"), _pin(wb, "dimension")),
        _row("  change per mm of tooth thickness", _pin(wf, "rate"), _pin(wb, "rate")),
        _row("smallest concave radius, mm", wf["smallest_concave_radius_mm"], wb["smallest_concave_radius_mm"]),
    ]
    methods = sorted(
        {w["span"]["method"] for w in (wf, wb) if w["span"] and w["span"].get("method")}
        | {w["pins"]["method"] for w in (wf, wb) if _pin_fits(w)}
    )
    thick = "; ".join(sorted({w.get("thickness_method", "closed form") for w in (wf, wb)}))
    lines.append(
        f"  (span and pins: {'; '.join(methods)}; thicknesses and concave radii: {thick};"
        " external teeth over pins, internal between pins)"
    )
    if any(w["smallest_concave_radius_mm"] == 0.0 for w in (wf, wb)):
        lines.append("  (a concave radius of 0: sharp root corner, or the cycloid's curvature at the pitch point)")
    outside = [key for key, g in (("flexspline", f), ("rigid", b)) if not g["pitch_circle_within_teeth"]]
    if outside:
        lines.append(
            f"  ({' and '.join(outside)}: the pitch circle lies outside the teeth, so no thickness is given there; "
            "report.json keeps the virtual values of the extended flanks)"
        )
    return lines


def _mesh_lines(rep: dict) -> list[str]:
    """The mesh on the major and minor axes, per coned section, and a warning for every radial collision."""
    m = rep["mesh"]
    lines = [
        f"  depth of engagement on the major axis: {m['depth_of_engagement_mm']:.4f} mm (w = {m['w_major_mm']:.4f} mm)",
        f"  radial clearance, major axis: flexspline tip {m['clearance_flex_tip_major_um']:.1f} um, "
        f"rigid tip {m['clearance_rigid_tip_major_um']:.1f} um",
        f"  radial tip gap, minor axis: {m['tip_gap_minor_um']:.1f} um (w = {m['w_minor_mm']:.4f} mm)",
        f"  exact vs first-order placement: {rep['placement']['exact_vs_first_order_um']:.3f} um "
        f"(W0^2/r_m = {rep['placement']['w0_squared_over_r_m_um']:.3f} um); "
        f"centre-line form [S3 eq. 15] on whole teeth: {rep['placement']['exact_vs_centreline_form_um']:.1f} um",
    ]
    for key, sec in rep.get("mesh_at_face_ends", {}).items():
        lines.append(
            f"  coning, section {key}: depth {sec['depth_of_engagement_mm']:.4f} mm, "
            f"flex tip clearance {sec['clearance_flex_tip_major_um']:.1f} um, minor tip gap {sec['tip_gap_minor_um']:.1f} um"
        )
    # a negative radial figure is a collision of tips with roots (or tips with tips on the minor axis): said, not
    # left to be read off a column (once: a section at -21.4 um went unflagged)
    sections = [("centre section", m)] + [(f"section {k}", sec) for k, sec in rep.get("mesh_at_face_ends", {}).items()]
    for where, sec in sections:
        bad = [
            (label, sec[key])
            for key, label in (
                ("clearance_flex_tip_major_um", "flexspline tip against the rigid root, major axis"),
                ("clearance_rigid_tip_major_um", "rigid tip against the flexspline root, major axis"),
                ("tip_gap_minor_um", "tips on the minor axis"),
            )
            if sec.get(key) is not None and sec[key] < 0
        ]
        for label, v in bad:
            lines.append(
                f"  WARNING ({where}): {label}: {v:.1f} um, the teeth collide radially there (wgcad audit shows where)"
            )
    return lines
