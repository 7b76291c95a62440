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


def summary_json(res: dict) -> dict:
    """The figures of :func:`run_sector` as JSON-ready data (angles deg, lengths mm, clearances um)."""
    lay, cf, sim = res["layout"], res["closed_form"], res["simulated"]
    cs = lay.coupling_sector_teeth()
    law = res["motion"]
    return {
        "closed_form_parameters": {
            "r_fix_mm": round(cf.r_fix, 6),
            "r_cr_mm": round(cf.r_cr, 6),
            "h_s_mm": round(cf.h_s, 6),
            "W0_mm": round(cf.w0, 6),
            "beta_deg": _deg(cf.beta),
            "full_height_mm": round(cf.full, 6),
            "generator_angle_rule": cf.rule,
        },
        "heights_built": res["mode"],
        "tip_clearance_um": round(1e3 * res["tip_clearance"], 4),
        "first_coupling_sector": {
            "teeth": [int(i) for i in cs],
            "closed_form_mm": [round(float(x), 6) for x in cf.heights[cs]],
            "closed_form_boundary_mm": [round(float(x), 6) for x in res["closed_form_boundary"].heights[cs]],
            "simulated_mm": [round(float(x), 6) for x in sim.heights[cs]],
            "difference_um": [round(1e3 * float(x), 4) for x in sim.heights[cs] - cf.heights[cs]],
        },
        "transmission_teeth_lowered": [
            int(i) for i in np.nonzero(~lay.coupling & (res["built"] < res["full"] - 1e-12))[0]
        ],
        "motion_law": {
            "phases": _phases_json(law),
            "runs": _runs_json(law),
            "output_per_turn_deg": round(float(np.rad2deg(law.advance)), 9),
        },
        "audit_full_height": sectored_audit_document(res["audit_full"]),
        "audit_built": sectored_audit_document(res["audit_built"]),
        "timing_s": {"closed_form": round(cf.elapsed_s, 4), "simulated": round(sim.elapsed_s, 4)},
    }


def heights_csv(res: dict) -> str:
    """Every tooth's heights: closed form (at its generator angle and at the boundary), simulated, built."""
    lay, cf, cfb, sim, built = (
        res["layout"],
        res["closed_form"],
        res["closed_form_boundary"],
        res["simulated"],
        res["built"],
    )
    cols = [
        "tooth",
        "sector",
        "kind",
        "index_in_sector",
        "centre_deg",
        "from_boundary_deg",
        "closed_form_mm",
        "assigned_generator_angle_deg",
        "tooth_angle_from_axis_deg",
        "w_mm",
        "closed_form_boundary_mm",
        "simulated_mm",
        "simulated_minus_closed_um",
        "built_mm",
    ]
    rows = []
    for i in range(lay.n_teeth):
        rows.append(
            [
                str(i),
                str(int(lay.sector[i])),
                lay.kinds[lay.sector[i]],
                str(int(lay.index[i])),
                f"{np.rad2deg(lay.centres[i]):.6f}",
                f"{np.rad2deg(lay.delta[i]):.6f}",
                f"{cf.heights[i]:.7f}",
                "" if not np.isfinite(cf.phi_h[i]) else f"{np.rad2deg(cf.phi_h[i]):.4f}",
                "" if not np.isfinite(cf.phi[i]) else f"{np.rad2deg(cf.phi[i]):.4f}",
                "" if not np.isfinite(cf.w[i]) else f"{cf.w[i]:.7f}",
                f"{cfb.heights[i]:.7f}",
                f"{sim.heights[i]:.7f}",
                f"{1e3 * (sim.heights[i] - cf.heights[i]):.4f}",
                f"{built[i]:.7f}",
            ]
        )
    return ",".join(cols) + "\n" + "\n".join(",".join(r) for r in rows) + "\n"


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


def sector_summary_text(name: str, res: dict, summ: dict, out) -> str:
    """The summary ``wgcad sector`` prints: heights both ways, motion law, the two audits, where the files went."""
    lines = []
    p = summ["closed_form_parameters"]
    fc = summ["first_coupling_sector"]
    lines.append(
        f"{name}: sectored rigid gear, {res['layout'].n_teeth} teeth in sectors {', '.join(res['layout'].kinds)}"
    )
    lines.append(
        f"  closed form h_i = r_fix - (r_cr + w(phi_i) + h_s): r_fix {p['r_fix_mm']:.4f} mm, r_cr {p['r_cr_mm']:.4f} mm, "
        f"h_s {p['h_s_mm']:.4f} mm, W0 {p['W0_mm']:.4f} mm, beta {p['beta_deg']} deg, full height {p['full_height_mm']:.4f} mm"
    )
    lines.append(f"    phi_i: {p['generator_angle_rule']}")
    lines.append("  first coupling sector, tooth heights (um): closed form | simulated | difference")
    for k, (a, b, dd) in enumerate(zip(fc["closed_form_mm"], fc["simulated_mm"], fc["difference_um"])):
        lines.append(f"    {k:3d}  {1e3 * a:8.2f}  {1e3 * b:8.2f}  {dd:+8.2f}")
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
    for key, label in (("audit_full", "full-height teeth"), ("audit_built", f"built heights ({res['mode']})")):
        a = res[key]
        where = ""
        if a.has_tip_to_tip:
            kinds = sorted({x.sector_kind for x in a.tip_to_tip})
            d = [round(float(np.rad2deg(x.from_boundary)), 4) for x in a.tip_to_tip]
            where = f" on {len(a.tip_to_tip)} teeth ({', '.join(kinds)}; {min(d):.2f} to {max(d):.2f} deg from a sector boundary)"
        tip = "TIP-TO-TIP" + where if a.has_tip_to_tip else "no tip-to-tip contact"
        lines.append(
            f"  audit, {label}: {tip}; smallest tip clearance {1e3 * a.min_tip_clearance:.2f} um, "
            f"smallest flank clearance {1e3 * a.min_flank_clearance:.2f} um{' (flank interference)' if a.flank_interference else ''}"
        )
    lines.append(
        f"  heights: closed form {res['closed_form'].elapsed_s:.2f} s, simulated {res['simulated'].elapsed_s:.2f} s; "
        f"sweep {res['step_deg']:g} deg over half a turn (identical waves; no mesh period)"
    )
    lines.append(
        f"  wrote heights, motion (CSV, PNG), sector audit PNG, sectored rigid gear DXF/STL and JSON to {out}/"
    )
    return "\n".join(lines) + "\n"
