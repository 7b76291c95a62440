"""Audit findings shaped for people and programs: the JSON document and the printed summary (docs/models.md 5)."""

from __future__ import annotations

import numpy as np

from wgcad import constants

__all__ = ["audit_json", "audit_summary", "worst_json", "entry_json", "backlash_at_json", "settings_json"]


def _deg(x, nd=6):
    return None if x is None else round(float(np.rad2deg(x)), nd)


def _z(z):
    return None if z is None else round(float(z), 6)


def worst_json(f) -> dict:
    """The tightest spot (a ``min_clearance`` :class:`~wgcad.clearance.findings.Finding`) for the JSON document."""
    mirror = f.details.get("mirror")  # None where errors break the mirror symmetry
    out = {
        "clearance_um": round(1e3 * f.value, 4),
        "tooth": f.tooth,
        "generator_angle_deg": _deg(f.generator_angle),
        "tooth_angle_deg": _deg(f.tooth_angle),
        "section_z_mm": _z(f.section_z),
        "location": f.location,
        "mirror": None if mirror is None else {"tooth_angle_deg": _deg(mirror[0]), "location": mirror[1]},
        "sample_tooth_angle_deg": _deg(f.details["sample_tooth_angle"]),
    }
    if "rigid_tooth" in f.details:
        out["rigid_tooth"] = int(f.details["rigid_tooth"])
    out.update(
        {
            "overlap_area_um2": round(1e6 * f.details["overlap_area"], 4),
            "polygon_clearance_um": None if f.polygon_value is None else round(1e3 * f.polygon_value, 4),
            "method": f.method,
        }
    )
    return out


def entry_json(gap, crossing, pinch, side: str) -> dict:
    """The entry: Delta of [S1] (``entry_gap``), the tip-circle crossing (``entry_crossing``) and the pinch after it
    (``entry_pinch``) for the JSON document (docs/models.md 5)."""
    crossed = bool(np.isfinite(gap.value))
    out = {
        "tooth_angle_deg": _deg(gap.tooth_angle) if crossed else None,
        "section_z_mm": _z(gap.section_z) if crossed else None,
        "edge": gap.details.get("edge") if crossed else None,
        "kind": gap.details.get("kind") if crossed else None,
        "location": gap.location if crossed else None,
        "side": side,
        "crossing_um": round(1e3 * crossing.value, 4) if np.isfinite(crossing.value) else None,
        "crossing_tooth_angle_deg": _deg(crossing.tooth_angle) if np.isfinite(crossing.value) else None,
        "crossing_section_z_mm": _z(crossing.section_z) if np.isfinite(crossing.value) else None,
        "crossing_edge": crossing.details.get("edge"),
    }
    if np.isfinite(pinch.value):
        out.update(
            {
                "pinch_um": round(1e3 * pinch.value, 4),
                "pinch_tooth_angle_deg": _deg(pinch.tooth_angle),
                "pinch_section_z_mm": _z(pinch.section_z),
                "pinch_location": pinch.location,
                "pinch_edge": pinch.details.get("edge"),
            }
        )
    else:
        out.update(
            {
                "pinch_um": None,
                "pinch_tooth_angle_deg": None,
                "pinch_section_z_mm": None,
                "pinch_location": None,
                "pinch_edge": None,
            }
        )
    out["tip_to_tip_risk"] = bool(
        gap.details.get("tip_to_tip_risk", False) or pinch.details.get("tip_to_tip_risk", False)
    )
    if "passages" in gap.details and isinstance(gap.details["passages"], list):
        out["sections"] = [
            {
                "section_z_mm": _z(p["section_z"]),
                "entry_gap_um": round(1e3 * p["delta"], 4) if np.isfinite(p["delta"]) else None,
                "tooth_angle_deg": _deg(p["delta_phi"]) if np.isfinite(p["delta"]) else None,
                "edge": p["edge"] or None,
                "kind": p["kind"] or None,
                "crossing_tooth_angle_deg": _deg(p["crossing"]) if np.isfinite(p["crossing"]) else None,
                "crossing_working_um": round(1e3 * p["crossing_gaps"][0], 4) if np.isfinite(p["crossing"]) else None,
                "crossing_non_working_um": round(1e3 * p["crossing_gaps"][1], 4)
                if np.isfinite(p["crossing"])
                else None,
            }
            for p in gap.details["passages"]
        ]
    if gap.details.get("note"):
        out["note"] = gap.details["note"]
    if crossing.tooth is not None:  # an imperfect drive: the passage the figures happen in
        out["tooth"] = int(crossing.tooth)
        out["generator_angle_deg"] = _deg(crossing.generator_angle)
        out["passages"] = int(crossing.details.get("passages", 0))
        out["spread_um"] = round(1e3 * crossing.details["spread"], 4) if "spread" in crossing.details else None
        if np.isfinite(pinch.value):
            out["pinch_tooth"] = int(pinch.tooth)
            out["pinch_generator_angle_deg"] = _deg(pinch.generator_angle)
    out["method"] = gap.method
    return out


def backlash_at_json(f) -> dict:
    """Where the backlash (a ``backlash`` finding) was computed."""
    return {"generator_angle_deg": _deg(f.generator_angle), "section_z_mm": _z(f.section_z)}


def _accuracy(run) -> dict:
    """The settings entries that say how exact an audit's figures are."""
    return {
        "chord_tol_um": round(1e3 * run.chord_tol, 6),
        "refined": run.refined,
        "refine_tol_um": round(1e3 * constants.REFINE_TOL, 6) if run.refined else None,
        "error_side": (
            "figures on the exact curves, within refine_tol_um either side"
            if run.refined
            else "polygon figures: chords lie inside convex and outside concave curve parts, "
            "so each figure is within 2 x chord_tol_um of the exact one, either side"
        ),
    }


def settings_json(run) -> dict:
    """What an audit ran with (:class:`~wgcad.clearance.findings.AuditRun`) as its JSON document states it."""
    A = len(run.angles)
    ends = run.face_ends_checked
    out = {
        "engine": "2d",
        "angles": int(A),
        "angle_step_deg": round(float(np.rad2deg(np.median(np.diff(run.angles)))), 6) if A > 1 else None,
        "sections_z_mm": [None if z is None else round(z, 6) for z in run.sections],
        "sections_note": (
            "identical sections (no coning): one computed"
            if not run.coned
            else "coned: every section computed" + ("" if ends else "; the face ends were NOT checked")
        ),
        "face_ends_checked": bool(ends),
        "mesh_period": run.mesh_period,
        "identical_waves": run.identical_waves,
        "mirror_symmetry": run.mirror_symmetry,
        "culling": run.culling,
        "branch_and_bound": run.branch_and_bound,
    }
    side = "entry (+phi)" if run.entry_sign > 0 else "entry (-phi)"
    imp = run.imperfect
    if imp is None:
        out.update(_accuracy(run))
        out.update(
            {"working_flank": run.working_flank, "entry_side": side, "rigid_pitch_radius_mm": run.rigid_pitch_radius}
        )
        return out
    out.update(
        {
            "imperfections": True,
            "generator_turns": round(imp.generator_turns, 6),
            "full_cycle_turns": imp.full_cycle_turns,
            "shortcuts_that_hold": dict(imp.shortcuts_that_hold),
            "shortcuts_note": (
                "imperfect parts: every (generator angle, tooth, section) sample posed with its errors, "
                f"in chunks of {imp.chunk} generator angles; bounds only along a tooth's track ({imp.why})"
            ),
        }
    )
    out.update(_accuracy(run))
    out.update(
        {"working_flank": run.working_flank, "rigid_pitch_radius_mm": run.rigid_pitch_radius, "entry_side": side}
    )
    return out


def audit_json(result) -> dict:
    """The JSON document of an :class:`~wgcad.clearance.engine.AuditResult` (units in the key names)."""
    r = result
    f = r.findings
    r_b = r.settings.rigid_pitch_radius
    finite_bl = np.isfinite(r.backlash)
    return {
        "min_clearance_um": round(1e3 * r.min_clearance, 4),
        "entry_gap_um": round(1e3 * r.entry_gap, 4) if np.isfinite(r.entry_gap) else None,
        "backlash_arcmin": None if not finite_bl else round(float(np.rad2deg(r.backlash) * 60.0), 5),
        "backlash_um_at_pitch": None if not finite_bl else round(1e3 * r.backlash * r_b, 4),
        "backlash_at": backlash_at_json(f["backlash"]),
        "backlash_unbounded": bool(np.isinf(r.backlash)),
        "interference": bool(r.interference),
        "interference_tol_um": round(1e3 * r.interference_tol, 4),
        "worst": worst_json(f["min_clearance"]),
        "entry": entry_json(f["entry_gap"], f.get("entry_crossing", f["entry_gap"]), f["entry_pinch"], r.entry_side),
        "settings": settings_json(r.settings),
        "counts": r.counts,
        "elapsed_s": round(r.elapsed_s, 4),
    }


def _spot(w: dict) -> str:
    """The worst spot folded to the nearest major axis, with its mirror image when that is the other flank."""
    s = f"{w['location']} at {w['tooth_angle_deg']:+.3f} deg from the nearest major axis"
    m = w.get("mirror")
    if m and m["location"] != w["location"]:
        s += f" (and, its mirror image, {m['location']} at {m['tooth_angle_deg']:+.3f} deg)"
    if w["section_z_mm"] is not None:
        s += f", section z = {w['section_z_mm']:g} mm"
    return s + f"; e.g. tooth {w['tooth']} at generator angle {w['generator_angle_deg']:.3f} deg"


def audit_summary(name: str, res: dict) -> str:
    """The printed summary of an audit's JSON document (:func:`audit_json`)."""
    w = res["worst"]
    st = res["settings"]
    lines = [f"{name}: clearance audit ({st['engine']} engine)"]
    lines.append(f"  minimum clearance: {res['min_clearance_um']:.3f} um, {_spot(w)}")
    if res["interference"]:
        lines.append(
            f"  INTERFERENCE: penetration {-res['min_clearance_um']:.3f} um deeper than the tolerance "
            f"{res['interference_tol_um']:g} um (overlap area {w['overlap_area_um2'] * 1e-6:.4g} mm^2)"
        )
    elif res["min_clearance_um"] < res["interference_tol_um"]:
        lines.append(f"  contact within the tolerance ({res['interference_tol_um']:g} um): no interference")
    else:
        lines.append("  no interference")
    e = res["entry"]
    if st.get("imperfections"):
        lines.append(_imperfect_line(st))
    if e.get("note"):
        pass  # not computed (imperfect parts): the caller's NOT CHECKED lines say so
    elif res["entry_gap_um"] is not None:
        lines += _entry_lines(res, e)
    else:
        lines.append("  entry gap: none (the tips never cross the rigid tip circle)")
    lines.append(_backlash_line(res))
    lines += _method_lines(res, st)
    return "\n".join(lines)


def _imperfect_line(st: dict) -> str:
    """What an imperfect drive's audit swept and which shortcuts still hold."""
    sh = st["shortcuts_that_hold"]
    held = [k.replace("_", " ") for k, v in sh.items() if v and k != "one_generator_turn"]
    turns = st.get("generator_turns", 1.0)
    cyc = (
        f"{turns:g} generator turn{'s' if turns != 1 else ''} of the {st['full_cycle_turns']}-turn cycle swept"
        if st.get("full_cycle_turns")
        else ""
    )
    if sh.get("one_generator_turn") and cyc:
        cyc += " (no flexspline-borne errors: one turn holds every state)"
    return (
        "  imperfect parts ([imperfections]): every tooth posed with its errors"
        + (f", {cyc}" if cyc else "")
        + "; shortcuts that still hold: "
        + (", ".join(held) if held else "none")
        + " (none used)"
    )


def _entry_lines(res: dict, e: dict) -> list[str]:
    """The entry gap Delta of [S1], the tip crossing and the pinch."""
    sec = "" if e["section_z_mm"] is None else f", section z = {e['section_z_mm']:g} mm"
    what = (
        "the pinch where the tips pass each other"
        if e["kind"] == "pinch"
        else "at the tip crossing (no pinch: the smallest gap of the entry)"
    )
    lines = [
        f"  entry gap Delta [S1]: {res['entry_gap_um']:.3f} um by the {e['edge']} flank ({e['location']}) at tooth angle "
        f"{e['tooth_angle_deg']:+.3f} deg{sec}, {what}" + ("  TIP-TO-TIP RISK" if e["tip_to_tip_risk"] else "")
    ]
    csec = "" if e["crossing_section_z_mm"] is None else f", section z = {e['crossing_section_z_mm']:g} mm"
    lines.append(
        f"  tip crossing: {e['crossing_um']:.3f} um by the {e['crossing_edge']} flank at tooth angle "
        f"{e['crossing_tooth_angle_deg']:+.3f} deg{csec} (flexspline tip circle meeting the rigid tip circle)"
        + (
            f"; tooth {e['tooth']} at generator angle {e['generator_angle_deg']:.3f} deg, the smallest of "
            f"{e['passages']} passages (they spread over {e['spread_um']:.3f} um)"
            if "tooth" in e
            else ""
        )
    )
    if e["pinch_um"] is None:
        lines.append(
            "  entry pinch: none (after the crossing the gaps never dip and rise again before the flanks engage)"
        )
    else:
        psec = "" if e["pinch_section_z_mm"] is None else f", section z = {e['pinch_section_z_mm']:g} mm"
        lines.append(
            f"  entry pinch: {e['pinch_um']:.3f} um by the {e['pinch_edge']} flank at tooth angle "
            f"{e['pinch_tooth_angle_deg']:+.3f} deg{psec}, {e['pinch_location']}"
            + (
                f"; tooth {e['pinch_tooth']} at generator angle {e['pinch_generator_angle_deg']:.3f} deg"
                if "pinch_tooth" in e
                else ""
            )
        )
    return lines


def _backlash_line(res: dict) -> str:
    b = res["backlash_at"]
    if res["backlash_arcmin"] is None:
        if res.get("backlash_unbounded"):
            return f"  backlash: unbounded (no flexspline tooth engages at generator angle {b['generator_angle_deg']:g} deg)"
        if res["interference"]:
            return f"  backlash: none, teeth interfere at generator angle {b['generator_angle_deg']:g} deg"
        return f"  backlash: none (the teeth touch at generator angle {b['generator_angle_deg']:g} deg)"
    return (
        f"  backlash: {res['backlash_arcmin']:.4f} arcmin = {res['backlash_um_at_pitch']:.2f} um at the rigid pitch circle "
        f"(generator angle {b['generator_angle_deg']:g} deg)"
    )


def _method_lines(res: dict, st: dict) -> list[str]:
    """How the figures were found: exact or polygon, the face ends, what was computed and how long it took."""
    if st.get("refined"):
        lines = [
            f"  figures refined on the exact tooth curves (to {st['refine_tol_um']:g} um either side; "
            f"outlines at {st['chord_tol_um']:g} um chords find where)"
        ]
    else:
        lines = [f"  polygon figures: within 2 x {st['chord_tol_um']:g} um of the exact curves' (either side)"]
    if st.get("face_ends_checked") is False:
        lines.append(f"  WARNING: coned flexspline, sections {st['sections_z_mm']} mm: the face ends were not checked")
    c = res["counts"]
    if "perfect_evaluated" in c:
        lines.append(
            f"  computed {c['evaluated']} of {c['samples']} tooth samples on polygons, {c.get('refined', 0)} on the exact curves "
            f"({c['culled']} ruled out by the perfect drive's bounds less the errors' reach, {c['perfect_evaluated']} "
            f"perfect-drive tooth angles evaluated for them) in {res['elapsed_s']:.3f} s"
        )
    else:
        lines.append(
            f"  computed {c['evaluated']} of {c['samples']} tooth samples on polygons, {c.get('refined', 0)} on the exact curves "
            f"({c['unique_tooth_angles']} distinct tooth angles, {c['culled']} culled by radius) in {res['elapsed_s']:.3f} s"
        )
    return lines
