"""The sectored rigid gear a design builds: its layout, the tooth heights of its rule and the outline every export
draws (docs/models.md 2.3). ``wgcad sector`` and the part set take the gear from here, so the DXF, STL and STEP of
both carry the same heights."""

from __future__ import annotations

import numpy as np

from ..errors import DesignError

__all__ = ["built_gear", "height_rule"]


def height_rule(mode: str, assign: str) -> str:
    """The rule that set the built heights, in words (``heights`` and ``assign`` of ``[sectors]``)."""
    if mode == "closed_form":
        where = (
            "the major axis on the sector boundary nearest the tooth ([S5] fig. 3)"
            if assign == "boundary"
            else "the major axis where a flexspline tip first faces the tooth (register)"
        )
        return f"[S5] formula h_i = r_fix - (r_cr + w(phi_i) + h_s), {where}, at most the full height"
    return {
        "simulated": "the largest height that keeps the tip clearance over the swept cycle",
        "full": "full height everywhere",
        "list": "the design's heights_mm",
    }[mode]


def built_gear(
    design,
    heights_mode: str | None = None,
    assign: str | None = None,
    step_deg: float | None = None,
    tip_clearance_um: float | None = None,
    drive=None,
) -> dict:
    """The sectored rigid gear of a design with ``[sectors]`` as built: only the heights its rule needs are computed.

    Returns a dict: ``drive``, ``layout``, ``teeth`` (:class:`~wgcad.profiles.sector.TeethByHeight`), ``full``
    (the full tooth height, mm), ``mode``, ``assign``, ``built`` (every tooth's height, mm), ``rule`` (in words),
    ``outline`` (the toothed boundary in the symmetric chord band the exports draw, docs/models.md appendix A),
    and the rule's own record: ``closed_form`` or ``simulated`` (None otherwise).

    Raises
    ------
    DesignError
        No ``[sectors]`` table; ``heights = "list"`` without ``heights_mm``.
    """
    from ..drive import build_drive, tooth_spec
    from ..profiles.sector import TeethByHeight, sector_layout, sectored_outline
    from .heights import closed_form_heights, listed_heights, simulated_heights
    from .scene import DEFAULT_STEP_DEG

    sp = design.sectors
    if not sp.active:
        raise DesignError(
            "sectors", "the design has no [sectors] table (a sectored rigid gear); see templates/d4_sectored.toml"
        )
    mode = heights_mode or sp.heights
    assign = assign or sp.assign
    step = DEFAULT_STEP_DEG if step_deg is None else step_deg
    drive = build_drive(design) if drive is None else drive
    d = design.drive
    layout = sector_layout(sp, d.z_flex, d.z_rigid)
    teeth = TeethByHeight(tooth_spec(design, "rigid"), drive.rigid, drive.tol)
    H = teeth.height
    cf = sim = None
    if mode == "closed_form":
        cf = closed_form_heights(drive, layout, teeth, assign=assign, step_deg=step)
        built = cf.heights
    elif mode == "simulated":
        c_req = 1e-3 * (sp.tip_clearance_um if tip_clearance_um is None else tip_clearance_um)
        sim = simulated_heights(drive, layout, teeth, c_req, step_deg=step)
        built = sim.heights
    elif mode == "full":
        built = np.full(layout.n_teeth, H)
    else:
        if sp.heights_mm is None:
            raise DesignError("sectors.heights_mm", "--heights list needs heights_mm in the design file")
        built = listed_heights(layout, sp.heights_mm, H)
    built = np.asarray(built, dtype=float)
    return {
        "drive": drive,
        "layout": layout,
        "teeth": teeth,
        "full": H,
        "mode": mode,
        "assign": assign,
        "built": built,
        "rule": height_rule(mode, assign),
        # the exported outline: every curve in a symmetric chord band (docs/models.md appendix A), as generate's
        "outline": sectored_outline(layout, teeth, built, band=True),
        "closed_form": cf,
        "simulated": sim,
    }
