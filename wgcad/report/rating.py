"""The datasheet of ``wgcad rating`` in words and as JSON (units in the keys; the only place its figures are rounded)."""

from __future__ import annotations

import numpy as np

from wgcad.rating.datasheet import CRITERIA
from wgcad.units import ARCMIN_PER_RAD, UM_PER_MM

from .friction import friction_document, friction_lines

__all__ = ["rating_document", "rating_lines"]


def _r(x, nd=1):
    if x is None or not np.isfinite(x):
        return None
    return round(float(x), nd)


def _stress(s) -> dict:
    return {
        "where": s.where,
        "section_z_mm": _r(s.z, 3),
        "nominal_bending_mpa": _r(s.nominal),
        "max_mpa": _r(s.sigma.max()),
        "min_mpa": _r(s.sigma.min()),
        "amplitude_mpa": _r(s.amplitude),
        "mean_mpa": _r(s.mean),
        "shear_mpa": _r(s.shear, 2),
        "goodman_safety": _r(s.safety, 3),
        "yield_safety": _r(s.yield_safety, 3),
        "largest_tension_at_deg": _r(np.rad2deg(s.peak_at), 2),
        "rated": s.rated,
    }


def _level(lv) -> dict:
    return {
        "torque_nm": _r(lv.torque_nm, 2),
        "goodman_safety": _r(lv.safety, 3),
        "yield_safety": _r(lv.yield_safety, 3),
        "bearing_l10_h": _r(lv.life_h, 0),
        "entry_gap_um": _r(UM_PER_MM * lv.entry_gap, 2),
        "engagement_depth_um": [_r(UM_PER_MM * x, 2) for x in lv.depth],
        "max_ball_pressure_mpa": _r(lv.max_pressure, 0),
        "wind_up_arcmin": _r(ARCMIN_PER_RAD * lv.state.wind_up, 4),
    }


def rating_document(ds, design_path: str) -> dict:
    """The datasheet as a JSON-ready dict."""
    st = ds.setup.strength
    lf = ds.rated.life
    fit = ds.fit
    ld = ds.design.load
    return {
        "design": design_path,
        "name": ds.design.drive.name,
        "rated_torque_nm": _r(ds.rated_torque_nm, 1),
        "rated": ds.rated_torque_nm > 0,
        "binding_criterion": ds.binding,
        "criteria": {
            k: {
                "asks": CRITERIA[k],
                "limit_torque_nm": _r(v.torque_nm, 1),
                "limit_is_above": v.above,
                "limit_bracket_nm": None if v.bracket is None else [_r(t, 1) for t in v.bracket],
                "note": v.note,
            }
            for k, v in ds.limits.items()
        },
        "input_speed_rpm": _r(ds.speed_rpm, 1),
        "cam_offset_um": ds.ratcheting["offset_um"],
        "cam_offset_deg": ds.ratcheting["offset_deg"],
        "flexspline": {
            "root_kt": _r(ds.kt.kt, 3),
            "root_kt_method": "plane-strain FE of a 5-tooth sector in pure bending (docs/models.md 10.2)",
            "root_kt_at_deg_from_tooth_centre": _r(np.rad2deg(ds.kt.angle), 3),
            "root_kt_at_radius_mm": _r(ds.kt.radius, 4),
            "notch_sensitivity": _r(ds.setup.q, 3),
            "root_kf": _r(ds.setup.kf, 3),
            # the plate rated: the part set's diaphragm (wgcad parts exports these sizes)
            "diaphragm_mm": None
            if ds.setup.plate is None
            else {
                "bolt_circle_diameter": _r(2.0 * ds.setup.plate.r_i, 4),
                "wall_radius": _r(ds.setup.plate.r_o, 4),
                "thickness": _r(ds.setup.plate.h, 4),
                "from_parts": ds.setup.plate_given,
            },
            "fillet_radius_mm": _r(ds.setup.rho_f, 4),
            "ultimate_mpa": st.ultimate,
            "yield_mpa": _r(st.yield_),
            "endurance_specimen_mpa": _r(st.endurance_specimen),
            "k_a": _r(st.k_a, 3),
            "k_b": _r(st.k_b, 3),
            "k_e": _r(st.k_e, 3),
            "endurance_mpa": _r(st.endurance),
            "assumed": list(st.assumed),
            "at_rated": [_stress(s) for s in ds.rated.stresses],
            "at_no_load": [_stress(s) for s in ds.levels[0].stresses],
        },
        "bearing": {
            "l10_h": _r(lf.l10_h, 0),
            "l10_million_rev": _r(lf.l10_mrev, 2),
            "relative_rpm": _r(lf.relative_rpm, 2),
            "mean_ball_load_inner_n": _r(lf.q_inner),
            "mean_ball_load_outer_n": _r(lf.q_outer),
            "raceway_rating_inner_n": _r(lf.q_ci, 0),
            "raceway_rating_outer_n": _r(lf.q_co, 0),
            "max_ball_pressure_mpa": _r(ds.rated.max_pressure, 0),
        },
        "stiffness": None
        if fit is None
        else {
            "t1_nm": _r(fit.t1),
            "t2_nm": _r(fit.t2),
            "k1_nm_per_rad": _r(fit.k1, 0),
            "k2_nm_per_rad": _r(fit.k2, 0),
            "k3_nm_per_rad": _r(fit.k3, 0),
            "fit_max_error_arcmin": _r(ARCMIN_PER_RAD * fit.max_error, 4),
            "fit_rms_error_arcmin": _r(ARCMIN_PER_RAD * fit.rms_error, 4),
            "curve": [{"torque_nm": _r(T, 2), "wind_up_arcmin": _r(ARCMIN_PER_RAD * th, 4)} for T, th in ds.curve],
        },
        "windup_offset_arcmin": None if ds.windup_offset is None else _r(ARCMIN_PER_RAD * ds.windup_offset, 3),
        "windup_offset_is": "twice the wind-up fit's intercept theta0 (both ways), not the audit's no-load backlash",
        "lost_motion_arcmin": None if ds.lost_motion is None else _r(ARCMIN_PER_RAD * ds.lost_motion, 3),
        "lost_motion_at_nm": _r(0.04 * ds.rated_torque_nm, 2),
        "natural_frequency_hz": _r(ds.natural_frequency_hz, 2),
        "output_inertia_kg_m2": ld.output_inertia_kg_m2,
        "ratcheting": {
            k: (_r(v, 1) if k == "torque_nm" else v)
            if not isinstance(v, dict)
            else {**v, "torque_nm": _r(v["torque_nm"], 1)}
            for k, v in ds.ratcheting.items()
        },
        "friction": friction_document(ds),
        "levels": [_level(lv) for lv in ds.levels],
        "not_checked": ds.notes,
        "warnings": list(ds.warnings),
        "timing_s": {k: _r(v, 3) for k, v in ds.timing.items()},
    }


def _limit_text(lim) -> str:
    """The limit with its resolution: a bisected one between the last torque met and the first failed."""
    text = f"{'> ' if lim.above else '  '}{lim.torque_nm:8.0f}"
    if lim.bracket is not None:
        lo, hi = lim.bracket
        text += f" (in {lo:.0f} .. {hi:.0f}, bisected to {hi - lo:.3g} N m, then interpolated)"
    return text


def rating_lines(ds) -> list[str]:
    """The datasheet as printed by ``wgcad rating``."""
    d = ds.design
    ld = d.load
    st = ds.setup.strength
    speed = ds.speed_rpm
    out = [
        f"{d.drive.name}: datasheet (elastic model, {len(ds.model.zs)} sections; input {speed:g} rpm; "
        f"cam offset {ds.ratcheting['offset_um']:g} um at {ds.ratcheting['offset_deg']:g} deg)",
        f"  RATED TORQUE {ds.rated_torque_nm:.0f} N m, bound by {ds.binding}: {CRITERIA[ds.binding]}"
        if ds.rated_torque_nm > 0
        else f"  NO RATED TORQUE: {ds.binding} fails at no load ({CRITERIA[ds.binding]})",
        "  limit of each criterion, N m ('>': still met where the model stops):",
    ]
    for k, lim in ds.limits.items():
        out.append(f"    {k:<15}{_limit_text(lim)}   {CRITERIA[k]}")
    out.append(
        f"  flexspline: tooth-root K_t {ds.kt.kt:.2f} (FE, peak {np.rad2deg(ds.kt.angle):.2f} deg from the tooth centre, "
        f"{UM_PER_MM * (ds.kt.radius - ds.setup.r_f):.0f} um above the root circle), q {ds.setup.q:.2f} -> K_f {ds.setup.kf:.2f}; "
        f"S_e {st.endurance:.0f} MPa = k_a {st.k_a:.2f} k_b {st.k_b:.2f} k_e {st.k_e:.2f} x S_e' {st.endurance_specimen:.0f} MPa"
    )
    if st.assumed:
        out.append(f"    assumed: {'; '.join(st.assumed)}")
    out.append(
        f"    stresses: nominal = the plain rim's largest bending stress E y dkappa; the range = the notch stress "
        f"(K_f {ds.setup.kf:.2f} x the rim's at the roots, plus the teeth's own bending)"
    )
    for label, lv in (("at no load", ds.levels[0]), (f"at {ds.rated_torque_nm:.0f} N m", ds.rated)):
        out.append(f"    {label}:")
        for s in lv.stresses:
            where = {
                "root": "tooth roots",
                "cup": "cup wall",
                "diaphragm_hub": "diaphragm at hub",
                "diaphragm_wall": "diaphragm at wall",
            }[s.where]
            where = f"{where} z {s.z:g} mm"
            out.append(
                f"      {where:<28} nominal {s.nominal:4.0f}, {s.sigma.min():7.0f} .. {s.sigma.max():5.0f} MPa (largest tension at "
                f"{np.rad2deg(s.peak_at):6.1f} deg), shear {s.shear:5.1f} MPa: Goodman safety {s.safety:.2f}, yield {s.yield_safety:.2f}"
                + ("" if s.rated else "  (not rated: derived sizes)")
            )
    lf = ds.rated.life
    out.append(
        f"  bearing at {ds.rated_torque_nm:.0f} N m: L10 {lf.l10_h:.0f} h ({lf.l10_mrev:.1f} million revolutions at "
        f"{lf.relative_rpm:.0f} rpm relative), mean ball loads {lf.q_inner:.0f} N (inner) {lf.q_outer:.0f} N (outer) "
        f"against raceway ratings {lf.q_ci:.0f} / {lf.q_co:.0f} N; largest pressure {ds.rated.max_pressure:.0f} MPa"
    )
    fit = ds.fit
    if fit is None:
        out.append("  stiffness, wind-up offset, lost motion: not computed (no rated torque to load the drive to)")
    else:
        out.append(
            f"  stiffness (wind-up from the elastic model, {len(ds.curve)} torques to the rated one; fit within "
            f"{ARCMIN_PER_RAD * fit.max_error * 60:.1f} arcsec): T1 {fit.t1:.0f} N m, T2 {fit.t2:.0f} N m, "
            f"K1 {fit.k1:.3g}, K2 {fit.k2:.3g}, K3 {fit.k3:.3g} N m/rad"
        )
        out.append(
            f"  wind-up offset (the stiffness fit's intercept, both ways; not the audit's backlash) "
            f"{ARCMIN_PER_RAD * ds.windup_offset:.2f} arcmin; lost motion at +-4 % of the "
            f"rated torque ({0.04 * ds.rated_torque_nm:.0f} N m) {ARCMIN_PER_RAD * ds.lost_motion:.2f} arcmin"
        )
    out += friction_lines(ds)
    fn = ds.natural_frequency_hz
    out.append(
        f"  first torsional natural frequency {fn:.1f} Hz (K1, output inertia {ld.output_inertia_kg_m2:g} kg m^2)"
        if fn is not None
        else "  natural frequency: not computed ([load] output_inertia_kg_m2 not given)"
    )
    r = ds.ratcheting
    out.append(
        f"  ratcheting (cam offset {r['offset_um']:g} um): {'above ' if r['above'] else ''}{r['torque_nm']:.0f} N m; {r['note']}"
    )
    if "no_offset" in r:
        r0 = r["no_offset"]
        out.append(f"    without the offset: {'above ' if r0['above'] else ''}{r0['torque_nm']:.0f} N m; {r0['note']}")
    elif r["offset_um"] == 0:
        out.append("    with a cam offset: not computed (none given: [load] cam_offset_um or --cam-offset-um)")
    for n in ds.warnings:
        out.append(f"  WARNING: {n}")
    for n in ds.notes:
        out.append(f"  NOT CHECKED: {n}")
    out.append(f"  {ds.timing['total_s']:.1f} s")
    return out
