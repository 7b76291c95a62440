"""The datasheet's friction rows in words and as JSON: efficiency, no-load running, starting and backdriving torque,
the hysteresis loop (docs/models.md 10.8)."""

from __future__ import annotations

import numpy as np

from wgcad.rating.friction import ASSUMPTIONS
from wgcad.units import ARCMIN_PER_RAD

__all__ = ["friction_document", "friction_lines"]


def _r(x, nd=3):
    if x is None or not np.isfinite(x):
        return None
    return round(float(x), nd)


def friction_document(ds) -> dict | None:
    """The friction block of the datasheet's JSON (None without a rated torque)."""
    fr = ds.friction
    if fr is None:
        return None
    su, eff, loop, rated = fr.setup, fr.efficiency, fr.loop, fr.rated
    lm_T = 0.04 * ds.rated_torque_nm
    b = rated.bearing()
    return {
        "tooth_friction": su.mu,
        "lubricant_viscosity_mm2_s": su.nu_cst,
        "viscous_friction_factor": su.f0,
        "seal_torque_nmm": su.seal_nmm,
        "bearing_static_rating_n": _r(su.c0_n, 0),
        "bearing_pitch_diameter_mm": _r(su.dm_mm, 3),
        "efficiency_at_rated": _r(rated.efficiency(), 4),
        "efficiency_at_rated_criterion": "output power / input power over a generator turn, at the input speed",
        "input_torque_at_rated_nm": _r(rated.input_torque_nm(), 4),
        "losses_at_rated_nmm_per_rad": {
            "teeth": _r(rated.teeth.loss, 3),
            "teeth_output_moment": _r(rated.teeth.output_moment, 3),
            "teeth_generator_moment": _r(rated.teeth.generator_moment, 3),
            "bearing_load_term": _r(b.load * su.ring_rate, 3),
            "bearing_viscous_term": _r(b.viscous * su.ring_rate, 3),
            "bearing_seals": _r(su.seal_nmm * su.ring_rate, 3),
        },
        "no_load_running_torque_nm": _r(eff.no_load_nm, 4),
        "no_load_running_torque_criterion": "input torque at zero output torque, at the input speed",
        "starting_torque_nm": _r(eff.starting_nm, 4),
        "starting_torque_criterion": "input torque at zero output torque at creep speed (Coulomb teeth, Palmgren's load term and low-speed viscous term)",
        "backdriving_torque_nm": _r(eff.backdriving_nm, 2),
        "backdriving_criterion": "output torque that turns the free input from rest at creep speed (None: self-locking over the range)",
        "self_locking": eff.self_locking,
        "efficiency_speeds_rpm": list(eff.speeds_rpm),
        "efficiency_curve": [
            {
                "torque_nm": _r(p.torque_nm, 2),
                "efficiency": [_r(x, 4) for x in row],
                "input_torque_nm": _r(p.input_torque_nm(), 4),
                "tooth_loss_nmm_per_rad": _r(p.teeth.loss, 3),
            }
            for p, row in zip(eff.points, eff.table)
        ],
        "hysteresis": {
            "loss_arcmin": _r(ARCMIN_PER_RAD * loop.hysteresis_loss, 3),
            "loss_criterion": "wind-up between the returns from +- the rated torque at zero torque (free play included)",
            "lost_motion_arcmin": _r(ARCMIN_PER_RAD * loop.lost_motion(lm_T), 3),
            "lost_motion_at_nm": _r(lm_T, 2),
            "width_nm": _r(loop.width_nm, 3),
            "cycle_energy_j": _r(loop.loss_j, 5),
            "loop": [
                {
                    "wind_up_arcmin": _r(ARCMIN_PER_RAD * th, 4),
                    "loading_nm": _r(up, 3),
                    "unloading_nm": _r(dn, 3),
                }
                for th, up, dn in zip(loop.theta, loop.loading, loop.unloading)
            ],
        },
        "assumed": list(ASSUMPTIONS),
    }


def friction_lines(ds) -> list[str]:
    """The friction rows as ``wgcad rating`` prints them."""
    fr = ds.friction
    if fr is None:
        return ["  efficiency, running and starting torque, hysteresis: not computed (no rated torque)"]
    su, eff, loop, rated = fr.setup, fr.efficiency, fr.loop, fr.rated
    b = rated.bearing()
    speeds = ", ".join(
        f"{e * 100:.1f} % at {n:g} rpm" for n, e in zip(eff.speeds_rpm, (rated.efficiency(n) for n in eff.speeds_rpm))
    )
    back = (
        "self-locking over the torques solved"
        if eff.self_locking
        else f"backdriving torque {eff.backdriving_nm:.1f} N m (at the output, the input free)"
    )
    lm_T = 0.04 * ds.rated_torque_nm
    return [
        f"  friction (teeth mu {su.mu:g}; bearing: Palmgren, viscosity {su.nu_cst:g} mm^2/s, f0 {su.f0:g}, "
        f"C0 {su.c0_n:.0f} N, dm {su.dm_mm:.1f} mm):",
        f"    efficiency at {ds.rated_torque_nm:.0f} N m: {speeds}",
        f"    losses at {ds.rated_torque_nm:.0f} N m, {ds.speed_rpm:g} rpm, per generator radian: teeth "
        f"{rated.teeth.loss:.1f} N mm, bearing load term {b.load * su.ring_rate:.1f} N mm, viscous term "
        f"{b.viscous * su.ring_rate:.1f} N mm"
        + (f", seals {su.seal_nmm * su.ring_rate:.1f} N mm" if su.seal_nmm else ", no seals")
        + f"; input torque {rated.input_torque_nm():.3f} N m",
        f"    no-load running torque {eff.no_load_nm:.3f} N m at {ds.speed_rpm:g} rpm; starting torque "
        f"{eff.starting_nm:.3f} N m (input, at creep speed); {back}",
        f"    hysteresis (generator held, +-{ds.rated_torque_nm:.0f} N m): loss {ARCMIN_PER_RAD * loop.hysteresis_loss:.2f} "
        f"arcmin at zero torque (free play included), lost motion at +-{lm_T:.0f} N m "
        f"{ARCMIN_PER_RAD * loop.lost_motion(lm_T):.2f} arcmin, width {loop.width_nm:.2f} N m, "
        f"{1e3 * loop.loss_j:.1f} mJ per cycle",
        "    assumed: " + "; ".join(ASSUMPTIONS),
    ]
