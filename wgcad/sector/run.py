"""The whole sectored rigid gear of a design as data: layout, tooth heights both ways, the gear as built, its motion
law and audits (docs/models.md 8). ``wgcad sector`` writes it; the part set builds the sectored rigid gear from it."""

from __future__ import annotations

from ..errors import DesignError

__all__ = ["run_sector"]


def run_sector(
    design,
    heights_mode: str | None = None,
    assign: str | None = None,
    step_deg: float | None = None,
    tip_clearance_um: float | None = None,
    progress=None,
    audits: bool = True,
) -> dict:
    """Everything ``wgcad sector`` computes, as data (no files): layout, heights both ways, built gear, motion law, audits.

    ``progress(fraction, stage)``, if given, is called before each step (fractions from the steps' times on D4).
    ``audits=False`` stops after the gear as built (the part set needs its outline, not its audits).
    """
    tick = progress or (lambda f, stage: None)
    import numpy as np

    from ..drive import build_drive, tooth_spec
    from ..profiles.sector import TeethByHeight, sector_layout, sectored_outline
    from . import (
        SectoredScene,
        closed_form_heights,
        listed_heights,
        motion_law,
        sectored_audit,
        simulated_heights,
    )
    from .scene import DEFAULT_STEP_DEG

    sp = design.sectors
    if not sp.active:
        raise DesignError(
            "sectors", "the design has no [sectors] table (a sectored rigid gear); see templates/d4_sectored.toml"
        )
    step = DEFAULT_STEP_DEG if step_deg is None else step_deg
    mode = heights_mode or sp.heights
    assign = assign or sp.assign
    c_req = 1e-3 * (sp.tip_clearance_um if tip_clearance_um is None else tip_clearance_um)
    drive = build_drive(design)
    d = design.drive
    layout = sector_layout(sp, d.z_flex, d.z_rigid)
    teeth = TeethByHeight(tooth_spec(design, "rigid"), drive.rigid, drive.tol)
    H = teeth.height
    tick(0.0, "closed-form heights")
    cf = closed_form_heights(drive, layout, teeth, assign=assign, step_deg=step)
    cf_b = closed_form_heights(drive, layout, teeth, assign="boundary") if assign != "boundary" else cf
    tick(0.03, "simulated heights")
    sim = simulated_heights(drive, layout, teeth, c_req, step_deg=step)
    if mode == "closed_form":
        built = cf.heights
    elif mode == "simulated":
        built = sim.heights
    elif mode == "full":
        built = np.full(layout.n_teeth, H)
    else:
        if sp.heights_mm is None:
            raise DesignError("sectors.heights_mm", "--heights list needs heights_mm in the design file")
        built = listed_heights(layout, sp.heights_mm, H)
    # the exported outline: every curve in a symmetric chord band (docs/models.md appendix A), as generate's
    outline = sectored_outline(layout, teeth, built, band=True)
    if not audits:
        return {
            "drive": drive,
            "layout": layout,
            "teeth": teeth,
            "full": H,
            "mode": mode,
            "built": np.asarray(built),
            "outline": outline,
        }
    tick(0.18, "motion law")
    law = motion_law(layout, d.z_flex)
    tick(0.19, "audit, full-height teeth")
    scene_full = SectoredScene(drive, layout, teeth, np.full(layout.n_teeth, H))
    audit_full = sectored_audit(scene_full, step)
    tick(0.53, "audit, built heights")
    audit_built = sectored_audit(SectoredScene(drive, layout, teeth, built), step)
    tick(0.8, "files")
    return {
        "drive": drive,
        "layout": layout,
        "teeth": teeth,
        "full": H,
        "closed_form": cf,
        "closed_form_boundary": cf_b,
        "simulated": sim,
        "mode": mode,
        "assign": assign,
        "built": np.asarray(built),
        "outline": outline,
        "motion": law,
        "audit_full": audit_full,
        "audit_built": audit_built,
        "step_deg": step,
        "tip_clearance": c_req,
    }
