"""How every tooth of a sectored rigid gear got its height: the rule, the generator angle and the flexspline tooth that
set it, the formula's terms, and the clearance the tooth keeps over the cycle (docs/models.md 2.3)."""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["ToothHeight", "height_records"]

#: a height this close to the full one is the full height, mm (the bisection of the simulated heights stops at 0.1 um)
_FULL_TOL = 1e-9


@dataclasses.dataclass(frozen=True)
class ToothHeight:
    """One rigid tooth's built height and where it comes from (lengths mm, angles rad; NaN or -1 where a field does
    not apply).

    Attributes
    ----------
    tooth, sector, index : int
        The tooth, its sector and its place in the sector.
    kind : str
        The sector's kind.
    centre, from_boundary : float
        The tooth's centre line, and its angle from the nearer boundary of its sector.
    height : float
        The built height, root to tip.
    set_by : str
        ``"formula"`` ([S5]'s closed form, lower than the full height), ``"formula: full"`` (the formula reaches
        the full height), ``"simulated"``, ``"simulated: full"`` (no facing tip limits it), ``"full"`` (the rule
        leaves the tooth alone: full height, e.g. a transmission tooth under the formula), ``"list"``.
    generator_angle : float
        The generator angle the rule took for the tooth.
    phi : float
        The tooth's angle from the major axis there (the formula's ``phi_h``: where ``w`` is taken).
    partner_flex_tooth : int
        The flexspline tooth facing it there: whose centre line stands nearest it (the simulated and register rules:
        the one of the sample that sets the height).
    partner_angle : float
        That flexspline tooth's own angle from the major axis there.
    w, r_ari, formula : float
        The closed form's terms: the neutral line's radial displacement at the tooth, the radius of the flexspline
        tip ``r_cr + w + h_s`` and the formula's height ``r_fix - r_ari`` before the cap.
    kept_clearance : float
        The smallest clearance of the tooth to any flexspline tooth over the audited cycle with the built heights
        (inf: no flexspline tooth comes within the sweep's culling distance).
    kept_generator_angle : float
    kept_flex_tooth : int
        Where that clearance is.
    """

    tooth: int
    sector: int
    index: int
    kind: str
    centre: float
    from_boundary: float
    height: float
    set_by: str
    generator_angle: float
    phi: float
    partner_flex_tooth: int
    partner_angle: float
    w: float
    r_ari: float
    formula: float
    kept_clearance: float
    kept_generator_angle: float
    kept_flex_tooth: int


def height_records(gear: dict, audit=None) -> list[ToothHeight]:
    """A :class:`ToothHeight` for every tooth of the gear :func:`wgcad.sector.built.built_gear` returns, with the
    kept clearances of ``audit`` (the sectored audit with those heights; None leaves them NaN)."""
    lay, built, H, mode = gear["layout"], gear["built"], gear["full"], gear["mode"]
    cf, sim = gear.get("closed_form"), gear.get("simulated")
    N = lay.n_teeth
    nan = np.full(N, np.nan)
    ang, phi, partner, p_ang, w, r_ari, raw = nan, nan, np.full(N, -1), nan, nan, nan, nan
    full = built >= H - _FULL_TOL
    if mode == "closed_form" and cf is not None:
        ang, phi, partner, p_ang, w, raw = cf.phi_h, cf.phi, cf.partner, cf.partner_phi, cf.w, cf.formula
        r_ari = cf.r_cr + cf.w + cf.h_s
        set_by = np.where(np.isfinite(ang), np.where(full, "formula: full", "formula"), "full")
    elif mode == "simulated" and sim is not None:
        ang, partner, p_ang = sim.worst_phi_h, sim.worst_flex, sim.worst_phi
        phi = p_ang
        set_by = np.where(full, "simulated: full", "simulated")
    else:
        set_by = np.full(N, mode)
    if audit is not None:
        kept, k_ang, k_flex = audit.per_tooth_min, audit.per_tooth_generator_angle, audit.per_tooth_flex
    else:
        kept, k_ang, k_flex = nan, nan, np.full(N, -1)
    return [
        ToothHeight(
            tooth=i,
            sector=int(lay.sector[i]),
            index=int(lay.index[i]),
            kind=str(lay.kinds[lay.sector[i]]),
            centre=float(lay.centres[i]),
            from_boundary=float(lay.delta[i]),
            height=float(built[i]),
            set_by=str(set_by[i]),
            generator_angle=float(ang[i]),
            phi=float(phi[i]),
            partner_flex_tooth=int(partner[i]),
            partner_angle=float(p_ang[i]),
            w=float(w[i]),
            r_ari=float(r_ari[i]),
            formula=float(raw[i]),
            kept_clearance=float(kept[i]),
            kept_generator_angle=float(k_ang[i]),
            kept_flex_tooth=int(k_flex[i]),
        )
        for i in range(N)
    ]
