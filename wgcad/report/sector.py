"""The sectored rigid gear's figures as documents: the summary JSON, the heights and motion-law tables (CSV) and
the summary text of ``wgcad sector`` (angles deg, lengths mm, clearances um; docs/models.md, theory 2.3)."""

from __future__ import annotations

import io

import numpy as np

__all__ = [
    "summary_json",
    "heights_csv",
    "motion_csv",
    "motion_phases_deg",
    "sector_summary_text",
    "sectored_audit_document",
    "transition_json",
    "loaded_csv",
]


def _deg(x):
    return None if x is None or not np.isfinite(x) else round(float(np.rad2deg(x)), 6)


def _spot(s) -> dict:
    """Where a sectored sweep found a figure (:class:`wgcad.sector.scene.SectorSpot`), um and deg; ``{}`` for none."""
    if s is None:
        return {}
    return {
        "clearance_um": round(1e3 * s.clearance, 4),
        "generator_angle_deg": round(float(np.rad2deg(s.generator_angle)), 6),
        "flex_tooth": s.flex_tooth,
        "flex_tooth_angle_from_axis_deg": round(float(np.rad2deg(s.flex_tooth_angle)), 4),
        "rigid_tooth": s.rigid_tooth,
        "sector": s.sector,
        "sector_kind": s.sector_kind,
        "tooth_in_sector": s.tooth_in_sector,
        "rigid_tooth_from_boundary_deg": round(float(np.rad2deg(s.from_boundary)), 4),
        "rigid_tooth_height_mm": round(s.rigid_tooth_height, 6),
    }


def _um_or_none(x):
    return round(1e3 * x, 4) if np.isfinite(x) else None


def sectored_audit_document(a) -> dict:
    """A sectored sweep's findings (:class:`wgcad.sector.scene.SectoredAudit`) as JSON: um and deg."""
    return {
        "tip_to_tip": a.has_tip_to_tip,
        "tip_to_tip_teeth": len(a.tip_to_tip),
        "tip_to_tip_at": [_spot(s) for s in a.tip_to_tip],
        "min_tip_clearance_um": _um_or_none(a.min_tip_clearance),
        "worst_tip": _spot(a.worst_tip),
        "min_clearance_um": round(1e3 * a.min_clearance, 4),
        "worst": _spot(a.worst),
        "flank_interference": bool(a.flank_interference),
        "interferes": bool(a.interferes),
        "min_flank_clearance_um": _um_or_none(a.min_flank_clearance),
        "interference_tol_um": round(1e3 * a.interference_tol, 4),
        "counts": a.counts,
        "settings": a.settings,
        "elapsed_s": round(a.elapsed_s, 4),
    }


def _phases_json(law) -> list:
    out = []
    for p in law.phases():
        out.append(
            {
                "kind": p.kind,
                "start_deg": _deg(p.start),
                "end_deg": _deg(p.end),
                "length_deg": _deg(p.length),
                "output_step_deg": round(float(np.rad2deg(p.output_step)), 9),
                "ratio": None if not np.isfinite(p.ratio) else round(float(p.ratio), 9),
            }
        )
    return out


def _runs_json(law) -> list:
    return [
        {
            "kind": p.kind,
            "start_deg": _deg(p.start),
            "end_deg": _deg(p.end),
            "length_deg": _deg(p.length),
            "output_step_deg": round(float(np.rad2deg(p.output_step)), 9),
            "mean_ratio": None if not np.isfinite(p.ratio) else round(float(p.ratio), 9),
        }
        for p in law.runs()
    ]


def _r(x, nd=6):
    return None if x is None or not np.isfinite(x) else round(float(x), nd)


def _tooth_json(t) -> dict:
    """One tooth's height and where it comes from (:class:`wgcad.sector.provenance.ToothHeight`), mm, deg, um."""
    return {
        "tooth": t.tooth,
        "sector": t.sector,
        "kind": t.kind,
        "index_in_sector": t.index,
        "centre_deg": _deg(t.centre),
        "from_boundary_deg": _deg(t.from_boundary),
        "height_mm": _r(t.height),
        "set_by": t.set_by,
        "generator_angle_deg": _deg(t.generator_angle),
        "angle_from_axis_deg": _deg(t.phi),
        "partner_flex_tooth": None if t.partner_flex_tooth < 0 else t.partner_flex_tooth,
        "partner_angle_from_axis_deg": _deg(t.partner_angle),
        "w_mm": _r(t.w, 7),
        "r_ari_mm": _r(t.r_ari, 7),
        "formula_mm": _r(t.formula, 7),
        "kept_clearance_um": _r(1e3 * t.kept_clearance, 4),
        "kept_at_generator_angle_deg": _deg(t.kept_generator_angle),
        "kept_with_flex_tooth": None if t.kept_flex_tooth < 0 else t.kept_flex_tooth,
    }


def _change_json(c) -> dict:
    return {
        "key": c.key,
        "value": _r(c.value),
        "was": _r(c.was),
        "min_clearance_um": _r(1e3 * c.min_clearance, 4),
        "tip_to_tip_teeth": None if c.tip_to_tip_teeth < 0 else c.tip_to_tip_teeth,
        "checked_at_step_deg": c.step_deg,
        "removes_interference": c.removes,
        "evaluations": c.evaluations,
        "note": c.note,
    }


def _arcsec(x):
    return None if x is None or not np.isfinite(x) else round(float(np.rad2deg(x)) * 3600.0, 3)


def transition_json(cy, fig, note: str) -> dict:
    """The transitions under load (:class:`wgcad.sector.transition.LoadedCycle` and its figures) as JSON: N, arcsec, deg."""
    if cy is None:
        return {"solved": False, "note": note}
    return {
        "solved": True,
        "torque_nm": cy.torque_nm,
        "states": len(cy.phi_h),
        "mesh_reach_deg": _deg(fig.reach),
        "steps_at_boundaries": fig.steps_boundary,
        "steps_interior": fig.steps_interior,
        "output_jump_at_boundary_arcsec": _arcsec(fig.output_jump_boundary),
        "output_jump_at_boundary_from_deg": _deg(fig.output_jump_boundary_at),
        "output_jump_interior_arcsec": _arcsec(fig.output_jump_interior),
        "output_deviation_range_arcsec": _arcsec(fig.output_range),
        "peak_force_jump_at_boundary_n": _r(fig.peak_force_jump_boundary, 3),
        "peak_force_jump_at_boundary_from_deg": _deg(fig.peak_force_jump_boundary_at),
        "peak_force_jump_interior_n": _r(fig.peak_force_jump_interior, 3),
        "tooth_force_jump_at_boundary_n": _r(fig.tooth_force_jump_boundary, 3),
        "tooth_force_jump_interior_n": _r(fig.tooth_force_jump_interior, 3),
        "peak_force_near_boundaries_n": _r(fig.peak_force_boundary, 3),
        "peak_force_interior_n": _r(fig.peak_force_interior, 3),
        "lowered_teeth_largest_force_n": _r(fig.lowered_force, 3),
        "lowered_teeth_largest_force_tooth": None if fig.lowered_tooth < 0 else fig.lowered_tooth,
        "lowered_teeth_largest_force_at_deg": _deg(fig.lowered_at),
        "flex_teeth_loaded": [int(x) for x in cy.flex_teeth],
        "contact_check_um": round(1e3 * cy.check_mm, 6),
        "largest_residual_rotation_arcsec": _arcsec(float(np.abs(cy.residual_rotation).max())),
        "seconds": round(cy.seconds, 3),
    }


def summary_json(res: dict) -> dict:
    """The figures of :func:`run_sector` as JSON-ready data (angles deg, lengths mm, clearances um)."""
    lay, cf, reg, sim = res["layout"], res["boundary"], res["register"], res["simulated"]
    cs = lay.coupling_sector_teeth()
    law = res["motion"]
    built = res["built"]
    ab = res["audit_built"]
    gap0 = cf.r_fix - cf.full - cf.r_cr - cf.h_s
    return {
        "closed_form_parameters": {
            "r_fix_mm": round(cf.r_fix, 6),
            "r_cr_mm": round(cf.r_cr, 6),
            "h_s_mm": round(cf.h_s, 6),
            "W0_mm": round(cf.w0, 6),
            "beta_deg": _deg(cf.beta),
            "full_height_mm": round(cf.full, 6),
            "tip_gap_mm": round(gap0, 6),
            "generator_angle_rule": cf.rule,
            "lowered_where": "w(phi_i) > r_fix - full height - r_cr - h_s (the tip gap of the undeformed teeth)",
        },
        "heights_built": res["mode"],
        "assign": res["assign"],
        "height_rule": res["rule"],
        "tip_clearance_um": round(1e3 * res["tip_clearance"], 4),
        "first_coupling_sector": {
            "teeth": [int(i) for i in cs],
            "formula_boundary_mm": [round(float(x), 6) for x in cf.heights[cs]],
            "formula_register_mm": [round(float(x), 6) for x in reg.heights[cs]],
            "simulated_mm": [round(float(x), 6) for x in sim.heights[cs]],
            "built_mm": [round(float(x), 6) for x in built[cs]],
            "lowered": int((built[cs] < res["full"] - 1e-9).sum()),
            "simulated_minus_formula_um": [round(1e3 * float(x), 4) for x in sim.heights[cs] - cf.heights[cs]],
        },
        "teeth": [_tooth_json(t) for t in res["teeth_records"]],
        "transmission_teeth_lowered": [int(i) for i in np.nonzero(~lay.coupling & (built < res["full"] - 1e-12))[0]],
        "motion_law": {
            "phases": _phases_json(law),
            "runs": _runs_json(law),
            "output_per_turn_deg": round(float(np.rad2deg(law.advance)), 9),
        },
        "audit_full_height": sectored_audit_document(res["audit_full"]),
        "audit_built": sectored_audit_document(ab),
        "runs": not ab.interferes,
        "design_changes": [_change_json(c) for c in res["remedies"]],
        "transitions_under_load": transition_json(res["loaded"], res["transition"], res["load_note"]),
        "timing_s": {
            "formula_register": round(reg.elapsed_s, 4),
            "simulated": round(sim.elapsed_s, 4),
        },
    }


def heights_csv(res: dict) -> str:
    """Every tooth's heights by each rule, the built one and how it was set (:class:`wgcad.sector.provenance.ToothHeight`)."""
    lay, cf, reg, sim, built = res["layout"], res["boundary"], res["register"], res["simulated"], res["built"]
    cols = [
        "tooth",
        "sector",
        "kind",
        "index_in_sector",
        "centre_deg",
        "from_boundary_deg",
        "formula_boundary_mm",
        "formula_register_mm",
        "simulated_mm",
        "simulated_minus_formula_um",
        "built_mm",
        "set_by",
        "generator_angle_deg",
        "angle_from_axis_deg",
        "partner_flex_tooth",
        "partner_angle_from_axis_deg",
        "w_mm",
        "r_ari_mm",
        "formula_uncapped_mm",
        "kept_clearance_um",
        "kept_at_generator_angle_deg",
        "kept_with_flex_tooth",
    ]

    def f(x, fmt):
        return "" if x is None or not np.isfinite(x) else format(x, fmt)

    rows = []
    for i, t in enumerate(res["teeth_records"]):
        rows.append(
            [
                str(i),
                str(int(lay.sector[i])),
                lay.kinds[lay.sector[i]],
                str(int(lay.index[i])),
                f"{np.rad2deg(lay.centres[i]):.6f}",
                f"{np.rad2deg(lay.delta[i]):.6f}",
                f"{cf.heights[i]:.7f}",
                f"{reg.heights[i]:.7f}",
                f"{sim.heights[i]:.7f}",
                f"{1e3 * (sim.heights[i] - cf.heights[i]):.4f}",
                f"{built[i]:.7f}",
                t.set_by,
                f(np.rad2deg(t.generator_angle), ".4f"),
                f(np.rad2deg(t.phi), ".4f"),
                "" if t.partner_flex_tooth < 0 else str(t.partner_flex_tooth),
                f(np.rad2deg(t.partner_angle), ".4f"),
                f(t.w, ".7f"),
                f(t.r_ari, ".7f"),
                f(t.formula, ".7f"),
                f(1e3 * t.kept_clearance, ".4f"),
                f(np.rad2deg(t.kept_generator_angle), ".4f"),
                "" if t.kept_flex_tooth < 0 else str(t.kept_flex_tooth),
            ]
        )
    return ",".join(cols) + "\n" + "\n".join(",".join(r) for r in rows) + "\n"


def loaded_csv(cy) -> str:
    """The loaded cycle, one row per state: generator angle, the outputs, the rim's rotation, forces."""
    lowered = np.asarray(cy.heights) < cy.heights.max() - 1e-9
    buf = io.StringIO()
    buf.write(
        "knot_deg,generator_angle_deg,output_kinematic_deg,output_loaded_deg,load_deviation_arcsec,"
        "rim_rotation_arcsec,flex_teeth_loaded,largest_tooth_force_n,largest_force_tooth,largest_lowered_tooth_force_n\n"
    )
    for k in range(len(cy.phi_h)):
        F = cy.rigid_forces[k]
        j = int(np.argmax(F))
        low = float(F[lowered].max()) if lowered.any() else 0.0
        buf.write(
            f"{np.rad2deg(cy.knots[k]):.4f},{np.rad2deg(cy.phi_h[k]):.6f},{np.rad2deg(cy.output_kinematic[k]):.9f},"
            f"{np.rad2deg(cy.output_loaded[k]):.9f},{np.rad2deg(cy.deviation[k]) * 3600:.4f},"
            f"{np.rad2deg(cy.rim_rotation[k]) * 3600:.4f},{int(cy.flex_teeth[k])},{F[j]:.4f},{j},{low:.4f}\n"
        )
    return buf.getvalue()


def motion_csv(law) -> str:
    """The motion law over a full generator turn, 0.1 deg steps: output rotation and phase (move or dwell)."""
    phi_h = np.linspace(0.0, 2.0 * np.pi, 3601)
    phi_g = law(phi_h)
    kind = np.full(len(phi_h), "move", dtype=object)
    for p in law.phases():
        if p.kind == "dwell":
            for shift in (0.0, 2 * np.pi, -2 * np.pi):
                kind[(phi_h >= p.start + shift - 1e-12) & (phi_h <= p.end + shift + 1e-12)] = "dwell"
    buf = io.StringIO()
    buf.write("generator_angle_deg,output_rotation_deg,phase\n")
    for a, g, k in zip(np.rad2deg(phi_h), np.rad2deg(phi_g), kind):
        buf.write(f"{a:.4f},{g:.9f},{k}\n")
    return buf.getvalue()


def motion_phases_deg(law) -> list:
    """The law's phases clipped to one turn 0..360 deg (a phase across 0 appears at both ends), for a picture."""
    ph = []
    for p in _phases_json(law):
        for shift in (-360.0, 0.0, 360.0):
            s, e = p["start_deg"] + shift, p["end_deg"] + shift
            if e > 0 and s < 360:
                ph.append({**p, "start_deg": max(s, 0.0), "end_deg": min(e, 360.0)})
    return ph


def _audit_lines(res: dict, summ: dict) -> list:
    """The summary's lines on the two audits, the design changes and the transitions under load."""
    lines = []
    for key, label in (("audit_full", "full-height teeth"), ("audit_built", f"built heights ({res['mode']})")):
        a = res[key]
        where = ""
        if a.has_tip_to_tip:
            kinds = sorted({x.sector_kind for x in a.tip_to_tip})
            d = [round(float(np.rad2deg(x.from_boundary)), 4) for x in a.tip_to_tip]
            where = f" on {len(a.tip_to_tip)} teeth ({', '.join(kinds)}; {min(d):.2f} to {max(d):.2f} deg from a sector boundary)"
        tip = "TIP-TO-TIP" + where if a.has_tip_to_tip else "no tip-to-tip contact"
        flank = ""
        if a.flank_interference and a.worst is not None:
            w = a.worst
            flank = (
                f" (FLANK INTERFERENCE: {w.sector_kind} tooth {w.tooth_in_sector}, flexspline tooth "
                f"{np.rad2deg(w.flex_tooth_angle):+.1f} deg from the axis)"
            )
        lines.append(
            f"  audit, {label}: {tip}; smallest tip clearance {1e3 * a.min_tip_clearance:.2f} um, "
            f"smallest flank clearance {1e3 * a.min_flank_clearance:.2f} um{flank}"
        )
    lines.append(
        "  the drive runs: no tip-to-tip contact, no flank interference over the whole cycle"
        if summ["runs"]
        else "  the drive does NOT run with the built heights"
    )
    for c in summ["design_changes"]:
        if c["value"] is None or c["min_clearance_um"] is None:
            lines.append(f"    {c['key']}: no value found ({c['note'] or 'no window within the scan'})")
            continue
        verdict = "removes it" if c["removes_interference"] else "does not remove it"
        lines.append(
            f"    design change: {c['key']} = {c['value']:g} (was {c['was']:g}) {verdict}: smallest clearance "
            f"{c['min_clearance_um']:+.2f} um over the cycle at {c['checked_at_step_deg']:g} deg steps"
        )
    tr = summ["transitions_under_load"]
    if tr["solved"]:
        lines.append(
            f"  under {tr['torque_nm']:g} N m ({tr['states']} states, the knots of half a turn): the load's part of the "
            f'output jumps by up to {tr["output_jump_at_boundary_arcsec"]:+.1f}" per step at a boundary '
            f'({tr["output_jump_interior_arcsec"]:+.1f}" inside the sectors; range {tr["output_deviation_range_arcsec"]:.1f}")'
        )
        lines.append(
            f"    largest tooth force jumps by {tr['peak_force_jump_at_boundary_n']:+.1f} N per step at a boundary "
            f"({tr['peak_force_jump_interior_n']:+.1f} N inside); largest force {tr['peak_force_near_boundaries_n']:.1f} N "
            f"near the boundaries, {tr['peak_force_interior_n']:.1f} N inside; on a lowered tooth "
            f"{tr['lowered_teeth_largest_force_n']:.1f} N"
        )
    else:
        lines.append(f"  transitions under load: {tr['note']}")
    return lines


def sector_summary_text(name: str, res: dict, summ: dict, out) -> str:
    """The summary ``wgcad sector`` prints: the heights and how they were set, the motion law, the two audits, the
    design change an interfering drive needs, the transitions under load, where the files went."""
    lines = []
    p = summ["closed_form_parameters"]
    fc = summ["first_coupling_sector"]
    lay = res["layout"]
    lines.append(f"{name}: sectored rigid gear, {lay.n_teeth} teeth in sectors {', '.join(lay.kinds)}")
    lines.append(
        f"  [S5] h_i = r_fix - (r_cr + w(phi_i) + h_s): r_fix {p['r_fix_mm']:.4f} mm, r_cr {p['r_cr_mm']:.4f} mm, "
        f"h_s {p['h_s_mm']:.4f} mm, W0 {p['W0_mm']:.4f} mm, beta {p['beta_deg']} deg, full height "
        f"{p['full_height_mm']:.4f} mm; lowered where w(phi_i) > tip gap {p['tip_gap_mm']:.4f} mm"
    )
    lines.append(f"  built: {res['mode']} ({summ['height_rule']}); {fc['lowered']} of {len(fc['teeth'])} teeth lowered")
    lines.append(
        "  first coupling sector (um): formula (boundary) | formula (register) | simulated | built | "
        "generator angle, flexspline tooth | kept clearance"
    )
    recs = {t["tooth"]: t for t in summ["teeth"]}
    for k, i in enumerate(fc["teeth"]):
        t = recs[i]
        how = (
            ""
            if t["generator_angle_deg"] is None
            else f"{t['generator_angle_deg']:7.2f} deg, {t['partner_flex_tooth']}"
        )
        kept = "" if t["kept_clearance_um"] is None else f"{t['kept_clearance_um']:+8.2f}"
        lines.append(
            f"    {k:3d}  {1e3 * fc['formula_boundary_mm'][k]:7.1f}  {1e3 * fc['formula_register_mm'][k]:7.1f}  "
            f"{1e3 * fc['simulated_mm'][k]:7.1f}  {1e3 * fc['built_mm'][k]:7.1f}  {t['set_by']:15s} {how:16s} {kept}"
        )
    if summ["transmission_teeth_lowered"]:
        lines.append(
            f"  transmission teeth also lowered (joint teeth out of register): {summ['transmission_teeth_lowered']}"
        )
    lines.append(f"  motion law: {summ['motion_law']['output_per_turn_deg']:.6f} deg of output per generator turn")
    for r in summ["motion_law"]["runs"][:4]:
        ratio = (
            "output still"
            if r["mean_ratio"] is None
            else f"output {r['output_step_deg']:+.6f} deg, mean u = {r['mean_ratio']:.4f}"
        )
        lines.append(
            f"    {r['kind']:5s} {r['start_deg']:9.4f} .. {r['end_deg']:9.4f} deg ({r['length_deg']:.4f} deg): {ratio}"
        )
    pieces = [p for p in summ["motion_law"]["phases"] if p["kind"] == "move"]
    seen, parts = set(), []
    for p_ in pieces:
        if p_["ratio"] not in seen:
            seen.add(p_["ratio"])
            parts.append(f"u = {p_['ratio']:.4g} over {p_['length_deg']:.4f} deg")
    lines.append(f"    speed ratio in the move pieces (d phi_h / d phi_g): {'; '.join(parts)}")
    lines += _audit_lines(res, summ)
    lines.append(
        f"  heights: register {res['register'].elapsed_s:.2f} s, simulated {res['simulated'].elapsed_s:.2f} s; "
        f"sweep {res['step_deg']:g} deg over half a turn (identical waves; no mesh period)"
    )
    loaded = "loaded transitions " if summ["transitions_under_load"]["solved"] else ""
    lines.append(
        f"  wrote heights, motion, {loaded}(CSV, PNG), sector audit PNG, sectored rigid gear DXF/STL and JSON to {out}/"
    )
    return "\n".join(lines) + "\n"
