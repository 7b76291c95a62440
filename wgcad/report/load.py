"""The load audit (``wgcad audit --torque-nm``) as a library call, its JSON document and its summary in words: the
only place its figures are rounded (units in the keys)."""

from __future__ import annotations

from math import pi

import numpy as np

from wgcad.constants import INTERFERENCE_TOL
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic.cam import cam_excess
from wgcad.elastic.model import build_model
from wgcad.elastic.sweep import LoadLevel, LoadSweep, law_departure, torque_sweep, wave_of
from wgcad.errors import DesignError

from .text import fixed

__all__ = ["level_document", "load_document", "load_lines", "load_run"]


def _deg(x):
    return round(float(np.rad2deg(x)), 4)


def _um(x, nd=4):
    return round(1e3 * float(x), nd)


def _entry(lv: LoadLevel, zs) -> list:
    out = []
    it = iter(lv.entry)
    for w, phase in enumerate((0.0, pi)):
        for z in zs:
            p = next(it)
            ok = bool(np.isfinite(p.delta))
            out.append(
                {
                    "wave": w,
                    "section_z_mm": float(z),
                    "entry_gap_um": _um(p.delta) if ok else None,
                    "tooth_angle_deg": _deg(p.delta_phi + phase) if ok else None,
                    "edge": p.delta_edge or None,
                    "kind": p.delta_kind or None,
                    "crossing_um": _um(min(p.crossing_gaps)) if ok else None,
                    "crossing_tooth_angle_deg": _deg(p.crossing + phase) if ok else None,
                }
            )
    return out


def _sections(lv: LoadLevel) -> list:
    st = lv.state
    m, c = st.model, st.contacts
    working = 1 if m.scene.working == "upper" else 0
    out = []
    for i in range(len(m.zs)):
        sel = lv.tooth & (c["section"] == i) & (c["force"] > 0)
        zone = []
        for w in (0, 1):
            sw = sel & (wave_of(c["phi"]) == w)
            if sw.any():
                ph = np.mod(c["phi"][sw] - w * pi + pi, 2 * pi) - pi
                zone.append([_deg(ph.min() + w * pi), _deg(ph.max() + w * pi)])
            else:
                zone.append(None)
        out.append(
            {
                "section_z_mm": float(m.zs[i]),
                "teeth_in_contact": int(len(np.unique(c["tooth"][sel]))),
                "working_flank_contacts": int((sel & (c["flank"] == working)).sum()),
                "non_working_flank_contacts": int((sel & (c["flank"] != working)).sum()),
                "zone_deg": zone,
            }
        )
    return out


def level_document(lv: LoadLevel) -> dict:
    """Figures of one load level (units in the keys)."""
    st = lv.state
    m, c = st.model, st.contacts
    tooth, F = lv.tooth, c["force"]
    entries = _entry(lv, m.zs)
    gaps = [e["entry_gap_um"] for e in entries if e["entry_gap_um"] is not None]
    cross = [e["crossing_um"] for e in entries if e["crossing_um"] is not None]
    at = min((e for e in entries if e["entry_gap_um"] is not None), key=lambda e: e["entry_gap_um"], default=None)
    per_tooth = lv.tooth_forces
    z_g = len(per_tooth)
    pen = -(c["gap"] + c["approach"])
    balls = lv.ball_loads
    return {
        "torque_nm": st.torque_nm,
        "entry_gap_um": min(gaps) if gaps else None,
        "entry_gap_at": None
        if at is None
        else {k: at[k] for k in ("wave", "section_z_mm", "tooth_angle_deg", "edge", "kind")},
        "crossing_gap_um": min(cross) if cross else None,
        "entry": entries,
        "min_clearance_um": _um(lv.min_clearance) if np.isfinite(lv.min_clearance) else None,
        "max_contact_approach_um": _um(c["approach"][tooth].max()) if tooth.any() else 0.0,
        "unexplained_penetration_um": _um(max(float(pen.max()), 0.0)),
        "teeth_in_contact": lv.teeth_in_contact,
        "sections": _sections(lv),
        "largest_tooth_force_n": round(float(per_tooth.max()), 3),
        "largest_contact_force_n": round(float(F[tooth].max()), 3) if tooth.any() else 0.0,
        "tooth_force_n": [round(float(x), 3) for x in per_tooth],
        "tooth_angle_deg": [_deg(x) for x in 2 * pi * np.arange(z_g) / z_g],
        "ball_load_n": [round(float(x), 3) for x in balls],
        "ball_angle_deg": [_deg(x) for x in c["phi"][~tooth]],
        "max_ball_load_n": round(float(balls.max()), 3),
        "max_ball_pressure_mpa": round(float(m.bearing.pressure(balls).max()), 1),
        "wind_up_arcmin": round(float(np.rad2deg(st.wind_up) * 60.0), 5),
        "generator_torque_nm": round(1e-3 * st.generator_torque, 6),
        "output_torque_over_ratio_nm": round(st.torque_nm / abs(m.scene.ratios["u_hg"]), 6),
        "mesh_wind_up_arcmin": round(float(np.rad2deg(st.mesh_wind_up) * 60.0), 5),
        "rim_shift_um": [_um(x) for x in st.rigid[:2]],
        "residuals": {k: (float(v) if not isinstance(v, int) else v) for k, v in st.residuals.items()},
        "timing_s": {k: round(v, 4) for k, v in st.timing.items()},
    }


def _mounted(sweep: LoadSweep) -> dict:
    model, mt = sweep.model, sweep.mounted
    dev, at = law_departure(model, mt)
    return {
        "w0_um": _um(mt.w0, 3),
        "cam_excess": round(cam_excess(model), 6),
        "largest_departure_from_law_um": _um(dev, 3),
        "departure_at_deg": _deg(at),
        "balls_in_contact": int((mt.force > 0).sum()),
        "ball_preload_n": round(float(mt.force.max()), 3),
    }


def _stiffness(values) -> list:
    """N mm/rad -> N m/rad, to 0.1."""
    return [None if v is None else round(1e-3 * v, 1) for v in values]


def load_document(sweep: LoadSweep) -> dict:
    """The load audit's JSON document: ``levels`` (:func:`level_document`), the secant stiffness from the first level
    and the tangent between neighbours, whether the entry gap closes, the model's figures and the settings."""
    model = sweep.model
    levels = [level_document(lv) for lv in sweep.levels]
    return {
        "levels": levels,
        "secant_stiffness_nm_per_rad": _stiffness(sweep.secant_stiffness()),
        "secant_from_torque_nm": sweep.levels[0].torque_nm if sweep.levels else None,
        "tangent_stiffness_nm_per_rad": _stiffness(sweep.tangent_stiffness()),
        "entry_gap_closes": sweep.entry_gap_closes,
        "interference_tol_um": 1e3 * INTERFERENCE_TOL,
        "cam_offset_um": sweep.cam_offset_um,
        "cam_offset_deg": sweep.cam_offset_deg,
        "model": {
            "ring_ei_n_mm2": {k: round(v, 1) for k, v in model.ei_parts.items()},
            # a cup without a length (no coning) is taken as rigid in torsion: no finite figure to give
            "cup_torsional_stiffness_nm_per_rad": (
                round(model.cup_stiffness * 1e-3, 1) if np.isfinite(model.cup_stiffness) else None
            ),
            "cup_torsional_stiffness_note": (
                None
                if np.isfinite(model.cup_stiffness)
                else "rigid: the design gives no cup length (generator.cone_length)"
            ),
            "bearing_clearance_um": _um(model.bearing.clearance, 3),
            "mounted": _mounted(sweep),
            "sections_z_mm": [float(z) for z in model.zs],
        },
        "elapsed_s": round(sweep.elapsed_s, 4),
        "summary_s": round(sweep.summary_s, 4),
    }


def load_run(path, torques, e_um=None, e_deg=None, sections: int = 3, progress=None):
    """The load audit of the design file ``path`` at ``torques`` (N m) with the cam offset ``e_um`` at ``e_deg``
    (default: the design's ``[load]``, else 0): the drive and the document (:func:`load_document`, with the design's
    name and file)."""
    drive = build_drive(load_design(path))
    if drive.design.imperfections.any:
        # the load audit models perfect parts: silently dropping the errors would report another drive
        raise DesignError(
            "imperfections",
            "the load audit (--torque-nm) models perfect parts and this design has "
            "[imperfections]: its KE under load is `wgcad ke --torque-nm`, its no-load clearance `wgcad audit` "
            "without --torque-nm; for the perfect drive's load audit remove the table",
        )
    ld = drive.design.load
    e_um = ld.cam_offset_um if e_um is None else e_um
    e_deg = ld.cam_offset_deg if e_deg is None else e_deg
    if e_um < 0:
        raise DesignError("--cam-offset-um", f"must be >= 0 um, got {e_um:g}")
    model = build_model(drive, sections)
    doc = load_document(torque_sweep(model, torques, e_um, e_deg, progress=progress))
    doc["design"] = drive.design.drive.name
    doc["source"] = drive.design.source
    return drive, doc


def load_lines(name: str, res: dict) -> str:
    """The load audit's summary in words, from its document (:func:`load_document`)."""
    lines = [
        f"{name}: under load (elastic contact model, {len(res['model']['sections_z_mm'])} sections), "
        f"cam offset {res['cam_offset_um']:g} um at {res['cam_offset_deg']:g} deg"
    ]
    mnt = res["model"].get("mounted")
    if mnt:
        lines.append(
            f"  on the cam at no load: W0 {mnt['w0_um']:.1f} um at the major axis (the design's), the rim within "
            f"{mnt['largest_departure_from_law_um']:.1f} um of the law (largest at {mnt['departure_at_deg']:+.1f} deg), "
            f"held by {mnt['balls_in_contact']} balls of {mnt['ball_preload_n']:.0f} N"
        )
    lines.append(
        "  torque N m | entry gap Delta um (where)           | tip crossing um | teeth in contact | max tooth force N | "
        "max ball load N | generator N m | wind-up arcmin | secant N m/rad | tangent N m/rad"
    )
    for k, lv in enumerate(res["levels"]):
        sec = res["secant_stiffness_nm_per_rad"][k]
        tan = res["tangent_stiffness_nm_per_rad"][k - 1] if k else None
        eg = "none" if lv["entry_gap_um"] is None else f"{lv['entry_gap_um']:9.3f}"
        at = lv.get("entry_gap_at")
        where = "" if not at else f"{at['tooth_angle_deg']:+6.1f} deg z {at['section_z_mm']:g} {at['edge']}"
        cr = "none" if lv.get("crossing_gap_um") is None else f"{lv['crossing_gap_um']:.3f}"
        lines.append(
            f"  {lv['torque_nm']:10g} | {eg:>9} {where:<25} | {cr:>15} | {lv['teeth_in_contact']:16d} | "
            f"{lv['largest_tooth_force_n']:17.1f} | {lv['max_ball_load_n']:15.1f} | {fixed(lv['generator_torque_nm'], 3, 13)} | "
            f"{fixed(lv['wind_up_arcmin'], 4, 14)} | "
            + ("-" if sec is None else f"{sec:14.4g}")
            + " | "
            + ("-" if tan is None else f"{tan:.4g}")
        )
    top = res["levels"][-1]
    lines.append(
        f"  at {top['torque_nm']:g} N m: smallest clearance of unloaded pairs "
        + ("-" if top["min_clearance_um"] is None else f"{top['min_clearance_um']:.3f} um")
        + f", largest contact approach (teeth pressed into each other, contact not interference) {top['max_contact_approach_um']:.3f} um"
        + f", largest ball Hertz pressure {top['max_ball_pressure_mpa']:.0f} MPa"
    )
    for sec in top["sections"]:
        zones = ", ".join("-" if z is None else f"{z[0]:+.1f}..{z[1]:+.1f} deg" for z in sec["zone_deg"])
        lines.append(
            f"    section z = {sec['section_z_mm']:g} mm: {sec['teeth_in_contact']} {'tooth' if sec['teeth_in_contact'] == 1 else 'teeth'} in contact "
            f"({sec['working_flank_contacts']} working, {sec['non_working_flank_contacts']} non-working flanks), zones per wave {zones}"
        )
    worst = max(lv["residuals"]["equilibrium"] for lv in res["levels"])
    lin = max(lv["residuals"]["linearisation_mm"] for lv in res["levels"])
    lines.append(
        f"  residuals: equilibrium {worst:.1e} (relative), nonlinear contact law {1e3 * lin:.3f} um; "
        f"{res['elapsed_s']:.2f} s"
    )
    if res["entry_gap_closes"]:
        lines.append("  ENTRY GAP CLOSES under load: tip interference")
    return "\n".join(lines)
