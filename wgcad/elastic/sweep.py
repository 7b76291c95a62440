"""A torque sweep of the loaded drive as data: entry gap, contacts, forces, ball loads, wind-up, stiffness (docs/models.md 4.1, 5)."""

from __future__ import annotations

import time
from math import pi

import numpy as np

from wgcad.constants import INTERFERENCE_TOL

from .cam import cam_excess, mounted
from .mesh import entry_gaps
from .model import ElasticModel
from .state import LoadState, solve_load

__all__ = ["level_summary", "torque_sweep"]


def _deg(x):
    return round(float(np.rad2deg(x)), 4)


def _wave_of(phi):
    """Index of the wave (major axis at 0 or pi) a tooth angle belongs to."""
    return (np.cos(phi) < 0.0).astype(int)


def _entry_laws(st: LoadState) -> list:
    """The laws whose entry gaps a level reports: each section, each wave."""
    return [law.shifted(phase) for phase in (0.0, pi) for law in st.laws]


def level_summary(st: LoadState, entry=None) -> dict:
    """Figures of one load state (units in the keys); ``entry``: its :func:`entry_gaps` if already computed."""
    m = st.model
    c = st.contacts
    tooth = c["kind"] == 1
    F = c["force"]
    working = 1 if m.scene.working == "upper" else 0
    entries = []
    gp = iter(entry if entry is not None else entry_gaps(m.scene, _entry_laws(st)))
    for w, phase in enumerate((0.0, pi)):
        for i, law in enumerate(st.laws):
            p = next(gp)
            ok = bool(np.isfinite(p.delta))
            entries.append(
                {
                    "wave": w,
                    "section_z_mm": float(m.zs[i]),
                    "entry_gap_um": round(1e3 * p.delta, 4) if ok else None,
                    "tooth_angle_deg": _deg(p.delta_phi + phase) if ok else None,
                    "edge": p.delta_edge or None,
                    "kind": p.delta_kind or None,
                    "crossing_um": round(1e3 * min(p.crossing_gaps), 4) if ok else None,
                    "crossing_tooth_angle_deg": _deg(p.crossing + phase) if ok else None,
                }
            )
    gaps = [e["entry_gap_um"] for e in entries if e["entry_gap_um"] is not None]
    cross = [e["crossing_um"] for e in entries if e["crossing_um"] is not None]
    at = min((e for e in entries if e["entry_gap_um"] is not None), key=lambda e: e["entry_gap_um"], default=None)
    sections = []
    for i in range(len(m.zs)):
        sel = tooth & (c["section"] == i) & (F > 0)
        zone = []
        for w in (0, 1):
            sw = sel & (_wave_of(c["phi"]) == w)
            if sw.any():
                ph = np.mod(c["phi"][sw] - w * pi + pi, 2 * pi) - pi
                zone.append([_deg(ph.min() + w * pi), _deg(ph.max() + w * pi)])
            else:
                zone.append(None)
        sections.append(
            {
                "section_z_mm": float(m.zs[i]),
                "teeth_in_contact": int(len(np.unique(c["tooth"][sel]))),
                "working_flank_contacts": int((sel & (c["flank"] == working)).sum()),
                "non_working_flank_contacts": int((sel & (c["flank"] != working)).sum()),
                "zone_deg": zone,
            }
        )
    # force per tooth (all sections and flanks), for the distribution
    tid = c["tooth"][tooth]
    per_tooth = np.zeros(m.drive.design.drive.z_flex)
    np.add.at(per_tooth, tid, F[tooth])
    z_g = len(per_tooth)
    phi_t = 2 * pi * np.arange(z_g) / z_g
    free = tooth & (F <= 0)
    pen = -(c["gap"] + c["approach"])
    return {
        "torque_nm": st.torque_nm,
        "entry_gap_um": min(gaps) if gaps else None,
        "entry_gap_at": None
        if at is None
        else {k: at[k] for k in ("wave", "section_z_mm", "tooth_angle_deg", "edge", "kind")},
        "crossing_gap_um": min(cross) if cross else None,
        "entry": entries,
        "min_clearance_um": round(1e3 * float(c["gap"][free].min()), 4) if free.any() else None,
        "max_contact_approach_um": round(1e3 * float(c["approach"][tooth].max()), 4) if tooth.any() else 0.0,
        "unexplained_penetration_um": round(1e3 * max(float(pen.max()), 0.0), 4),
        "teeth_in_contact": int(len(np.unique(c["tooth"][tooth & (F > 0)]))),
        "sections": sections,
        "largest_tooth_force_n": round(float(per_tooth.max()), 3),
        "largest_contact_force_n": round(float(F[tooth].max()), 3) if tooth.any() else 0.0,
        "tooth_force_n": [round(float(x), 3) for x in per_tooth],
        "tooth_angle_deg": [_deg(x) for x in phi_t],
        "ball_load_n": [round(float(x), 3) for x in F[~tooth]],
        "ball_angle_deg": [_deg(x) for x in c["phi"][~tooth]],
        "max_ball_load_n": round(float(F[~tooth].max()), 3),
        "max_ball_pressure_mpa": round(float(m.bearing.pressure(F[~tooth]).max()), 1),
        "wind_up_arcmin": round(float(np.rad2deg(st.wind_up) * 60.0), 5),
        "generator_torque_nm": round(1e-3 * st.generator_torque, 6),
        "output_torque_over_ratio_nm": round(st.torque_nm / abs(m.scene.ratios["u_hg"]), 6),
        "mesh_wind_up_arcmin": round(float(np.rad2deg(st.mesh_wind_up) * 60.0), 5),
        "rim_shift_um": [round(1e3 * float(x), 4) for x in st.rigid[:2]],
        "residuals": {k: (float(v) if not isinstance(v, int) else v) for k, v in st.residuals.items()},
        "timing_s": {k: round(v, 4) for k, v in st.timing.items()},
    }


def mounted_summary(model: ElasticModel, e) -> dict:
    """The rim on the cam at no load (before the mesh): its W0, how far it departs from the design's law, the balls holding it."""
    mt = mounted(model, e)
    tab = model.tables
    phi = tab.angles[: tab.z_g]
    el = tab.tooth_field(mt.loads)
    w = el[0] + mt.rigid[0] * np.cos(phi) + mt.rigid[1] * np.sin(phi)
    law = model.drive.law.state(phi).w
    dev = w - law
    i = int(np.argmax(np.abs(dev)))
    return {
        "w0_um": round(1e3 * mt.w0, 3),
        "cam_excess": round(cam_excess(model), 6),
        "largest_departure_from_law_um": round(1e3 * float(dev[i]), 3),
        "departure_at_deg": _deg(phi[i]),
        "balls_in_contact": int((mt.force > 0).sum()),
        "ball_preload_n": round(float(mt.force.max()), 3),
    }


def torque_sweep(
    model: ElasticModel,
    torques_nm,
    cam_offset_um: float = 0.0,
    cam_offset_deg: float = 0.0,
    tol: float | None = None,
    progress=None,
) -> dict:
    """Solve every torque level (each warm-started from the previous) and summarise.

    Returns
    -------
    dict with ``levels`` (list of :func:`level_summary`), ``secant_stiffness_nm_per_rad`` and ``tangent_stiffness_nm_per_rad``
    (secant between neighbouring levels), ``entry_gap_closes`` (bool) and settings.
    """
    kw = {} if tol is None else {"tol": tol}
    levels, states = [], []
    prev = None
    t0 = time.perf_counter()
    for k, T in enumerate(torques_nm):
        st = solve_load(model, float(T), cam_offset_um, cam_offset_deg, warm=prev, **kw)
        prev = st
        states.append(st)
        if progress:
            progress(k + 1, len(torques_nm), "load levels")
    # the entry gaps of every level refined on the exact curves in one engine call (its cost is per call)
    t1 = time.perf_counter()
    n_e = 2 * len(model.zs)
    gaps = entry_gaps(model.scene, [law for st in states for law in _entry_laws(st)])
    levels = [level_summary(st, gaps[k * n_e : (k + 1) * n_e]) for k, st in enumerate(states)]
    t_summary = time.perf_counter() - t1
    # stiffness as catalogues state it: secant from the first level (zero load when the sweep starts there) and
    # tangent, estimated by the increment between neighbouring levels
    secant, tangent = [], []
    for st in states:
        dth = st.wind_up - states[0].wind_up
        secant.append(round((st.torque_nm - states[0].torque_nm) / dth, 1) if dth > 0 else None)
    for a, b in zip(states[:-1], states[1:]):
        dth = b.wind_up - a.wind_up
        tangent.append(round((b.torque_nm - a.torque_nm) / dth, 1) if dth > 0 else None)
    closes = any(lv["entry_gap_um"] is not None and lv["entry_gap_um"] < -1e3 * INTERFERENCE_TOL for lv in levels)
    return {
        "levels": levels,
        "secant_stiffness_nm_per_rad": secant,
        "secant_from_torque_nm": states[0].torque_nm if states else None,
        "tangent_stiffness_nm_per_rad": tangent,
        "entry_gap_closes": bool(closes),
        "interference_tol_um": 1e3 * INTERFERENCE_TOL,
        "cam_offset_um": cam_offset_um,
        "cam_offset_deg": cam_offset_deg,
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
            "bearing_clearance_um": round(1e3 * model.bearing.clearance, 3),
            "mounted": mounted_summary(model, states[0].cam_offset if states else np.zeros(2)),
            "sections_z_mm": [float(z) for z in model.zs],
        },
        "elapsed_s": round(time.perf_counter() - t0, 4),
        "summary_s": round(t_summary, 4),
        "states": states,
    }
