"""The 3D check (``wgcad audit --engine fcl``) as JSON and in words: its records rounded, units in the keys."""

from __future__ import annotations

import numpy as np

from wgcad.clearance.fcl3d import Check3D, PairCheck, ToothCheck

__all__ = ["check3d_document", "tooth_check_document"]


def _um(x):
    return round(1e3 * float(x), 6)


def _pair(r: PairCheck) -> dict:
    row = {
        "rigid_tooth": r.rigid_tooth,
        "fcl_distance_um": _um(r.fcl_distance),
        "fcl_overlap": r.fcl_overlap,
        "clearance_2d_um": _um(r.clearance_2d),
        "bound_um": None if r.bound is None else _um(r.bound),
    }
    if r.witness_z is not None:
        row["fcl_witness_z_mm"] = round(r.witness_z, 6)
        row["clearance_2d_at_witness_um"] = _um(r.clearance_2d_at_witness)
    row["agree"] = r.agree
    return row


def tooth_check_document(t: ToothCheck) -> dict:
    """One tooth's 3D check (um, mm, deg, ms): FCL against the 2D engine, per rigid tooth too."""
    out = {} if t.what is None else {"what": t.what}
    out.update(
        {
            "tooth_angle_deg": round(float(np.rad2deg(t.tooth_angle)), 6),
            "rigid_teeth": t.rigid_teeth,
            "fcl_distance_um": _um(t.fcl_distance),
            "fcl_overlap": t.fcl_overlap,
            "clearance_2d_um": _um(t.clearance_2d),
            "sections_z_mm": None if t.sections_z is None else [round(z, 6) for z in t.sections_z],
            "bound_um": None if t.bound is None else _um(t.bound),
            "loft_error_um": round(1e3 * t.loft_error, 9),
            "agree": t.agree,
            "per_tooth": [_pair(r) for r in t.per_tooth],
        }
    )
    if t.witness_z is not None:
        out["fcl_witness_z_mm"] = round(t.witness_z, 6)
        out["clearance_2d_at_witness_um"] = _um(t.clearance_2d_at_witness)
    out["timing_ms"] = {
        "2d": round(1e3 * t.timing["2d"], 3),
        "fcl_total": round(1e3 * t.timing["fcl_total"], 3),
        "fcl_per_query": [round(1e3 * q, 3) for q in t.timing["fcl_per_query"]],
    }
    if t.generator_angle is not None:
        out["generator_angle_deg"] = round(float(np.rad2deg(t.generator_angle)), 6)
        out["tooth"] = t.tooth
    return out


def check3d_document(c: Check3D) -> dict:
    """The 3D check's JSON: ``pairs`` (:func:`tooth_check_document`), ``n_sections``, ``agree`` and a one-line
    ``summary``."""
    pairs = [tooth_check_document(t) for t in c.pairs]
    parts = []
    for p in pairs:
        f = "overlap" if p["fcl_overlap"] else f"{p['fcl_distance_um']:.4f} um"
        b = f" (bound {p['bound_um']:.3g} um)" if c.coned and not p["fcl_overlap"] else ""
        who = (
            f" (tooth {p['tooth']} at generator angle {p['generator_angle_deg']:.3f} deg, parts with their errors)"
            if "tooth" in p
            else ""
        )
        parts.append(
            f"{p['what']} at {p['tooth_angle_deg']:.3f} deg{who}: FCL {f} vs 2D {p['clearance_2d_um']:.4f} um{b}"
        )
    secs = f"{c.n_sections} sections" if c.coned else "prisms (no coning)"
    summary = ("agree" if c.agree else "DISAGREE") + f", {secs}: " + "; ".join(parts)
    return {"pairs": pairs, "n_sections": c.n_sections, "agree": c.agree, "summary": summary}
