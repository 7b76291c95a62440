"""The whole sectored rigid gear of a design as data: layout, tooth heights by every rule, the gear as built and how
each tooth got its height, its motion law, the audits over the cycle, the design change that lets an interfering drive
run, and the transitions under load (docs/models.md 2.3). ``wgcad sector`` writes it."""

from __future__ import annotations

from ..errors import DesignError

__all__ = ["run_sector", "load_torque"]


def load_torque(design, torque_nm: float | None):
    """The torque of the loaded transitions: ``torque_nm``, else ``[load] rated_torque_nm``; None when there is none
    or the design lacks what the elastic model needs (``[material]``, ``[bearing]``), with the reason.

    Raises
    ------
    DesignError
        ``torque_nm`` given but the design cannot be loaded (the missing key named).
    """
    from ..design.load import require_bearing

    T = torque_nm if torque_nm is not None else design.load.rated_torque_nm
    if T is None:
        return None, "no torque: give [load] rated_torque_nm or --torque-nm"
    try:
        require_bearing(design)
    except DesignError as e:
        if torque_nm is not None:
            raise
        return None, f"not solved: {e}"
    if not T > 0:
        raise DesignError(
            "--torque-nm" if torque_nm is not None else "load.rated_torque_nm", f"must be > 0 N m, got {T:g}"
        )
    return float(T), ""


def run_sector(
    design,
    heights_mode: str | None = None,
    assign: str | None = None,
    step_deg: float | None = None,
    tip_clearance_um: float | None = None,
    progress=None,
    audits: bool = True,
    torque_nm: float | None = None,
    load: bool = True,
    remedy: bool = True,
) -> dict:
    """Everything ``wgcad sector`` computes, as data (no files).

    Keys: those of :func:`wgcad.sector.built.built_gear` (the gear as built); ``boundary``, ``register`` (the
    closed form with either generator-angle rule), ``simulated``; ``motion``; ``audit_full``, ``audit_built``;
    ``teeth_records`` (:func:`wgcad.sector.provenance.height_records`); ``remedies`` (a list of
    :class:`~wgcad.sector.remedy.DesignChange`, empty when the built drive runs or ``remedy`` is off);
    ``loaded`` (:class:`~wgcad.sector.transition.LoadedCycle` or None), ``transition``
    (:class:`~wgcad.sector.transition.TransitionFigures` or None), ``load_note``; ``step_deg``, ``tip_clearance``.

    ``progress(fraction, stage)``, if given, is called before each step (fractions from the steps' times on D4).
    ``audits=False`` stops after the gear as built. ``load=False`` skips the loaded transitions.
    """
    tick = progress or (lambda f, stage: None)
    import numpy as np

    from . import SectoredScene, closed_form_heights, motion_law, sectored_audit, simulated_heights
    from .built import built_gear
    from .provenance import height_records
    from .scene import DEFAULT_STEP_DEG

    sp = design.sectors
    step = DEFAULT_STEP_DEG if step_deg is None else step_deg
    c_req = 1e-3 * (sp.tip_clearance_um if tip_clearance_um is None else tip_clearance_um)
    T, note = (None, "not asked") if not (audits and load) else load_torque(design, torque_nm)
    tick(0.0, "built heights")
    gear = built_gear(design, heights_mode, assign, step, tip_clearance_um)
    if not audits:
        return gear
    drive, layout, teeth, H = gear["drive"], gear["layout"], gear["teeth"], gear["full"]
    tick(0.01, "closed-form heights")
    cf = {}
    for rule in ("boundary", "register"):
        mine = gear["closed_form"]
        cf[rule] = mine if mine is not None and gear["assign"] == rule else None
        if cf[rule] is None:
            cf[rule] = closed_form_heights(drive, layout, teeth, assign=rule, step_deg=step)
    tick(0.04, "simulated heights")
    sim = gear["simulated"] if gear["simulated"] is not None else simulated_heights(drive, layout, teeth, c_req, step)
    tick(0.08, "audit, full-height teeth")
    law = motion_law(layout, design.drive.z_flex)
    audit_full = sectored_audit(SectoredScene(drive, layout, teeth, np.full(layout.n_teeth, H)), step)
    tick(0.29, "audit, built heights")
    audit_built = sectored_audit(SectoredScene(drive, layout, teeth, gear["built"]), step)
    changes = []
    if remedy and audit_built.interferes:
        tick(0.5, "design change that removes the interference")
        from .remedy import remedies

        changes = remedies(design, gear["mode"], gear["assign"], step, tip_clearance_um, audit_result=audit_built)
    loaded = trans = None
    if T is not None:
        from .transition import loaded_cycle, transition_figures

        tick(0.5, "transitions under load")
        loaded = loaded_cycle(gear, T, progress=lambda k, n: tick(0.5 + 0.47 * k / n, "transitions under load"))
        trans = transition_figures(loaded, layout, H)
    tick(0.97, "files")
    return {
        **gear,
        "boundary": cf["boundary"],
        "register": cf["register"],
        "simulated": sim,
        "motion": law,
        "audit_full": audit_full,
        "audit_built": audit_built,
        "teeth_records": height_records(gear, audit_built),
        "remedies": changes,
        "loaded": loaded,
        "transition": trans,
        "torque_nm": T,
        "load_note": note,
        "step_deg": step,
        "tip_clearance": c_req,
    }
