"""Design file -> drive -> clearance audit, with the settings a run (or a baseline) names.

The library's users reach it as :mod:`wgcad.audit` (``from wgcad.audit import RunSettings``; called,
``wgcad.audit(design, settings)`` is :func:`wgcad.api.audit`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..clearance.engine import AuditSettings, audit
from ..clearance.imperfect import audit_imperfect, chunk_angles
from ..design import load_design
from ..design.budget import DEFAULT_MAX_MEMORY_MB, RunShape
from ..drive import build_drive
from ..errors import DesignError
from ..numbers import Bound
from ..placement.imperfect import Imperfections, full_cycle_turns

__all__ = ["BOUNDS", "RunSettings", "run_audit"]


#: the range of each numeric setting: RunSettings.check and the CLI's flags (wgcad.cli.bounds) state the same rule
BOUNDS = {
    "step_deg": Bound(1e-4, 90.0, "deg"),
    "sections": Bound(1, 200, "sections", whole=True),
    "chord_tol_um": Bound(0.0, 100.0, "um", lo_open=True),
    "turns": Bound(1, 10_000, "generator turns", whole=True),  # or None: the whole cycle
    "interference_tol_um": Bound(0.0, 1000.0, "um"),
}


@dataclass(frozen=True)
class RunSettings:
    """Settings of an audit run as a user gives them (units in the names)."""

    step_deg: float = 0.5  # generator-angle step over one full revolution
    sections: int = 3  # cross-sections over the face width (used when the flexspline is coned)
    chord_tol_um: float = 1.0
    interference_tol_um: float = 1.0
    use_period: bool = True
    use_waves: bool = True
    use_mirror: bool = True
    cull: bool = True
    bound: bool = True
    max_memory_mb: float | None = DEFAULT_MAX_MEMORY_MB  # refuse runs estimated above this (None: no limit)
    refine: bool = True  # figures on the exact tooth curves
    #: generator turns swept for an imperfect drive (None: the whole cycle,
    #: placement.imperfect.full_cycle_turns); a perfect drive repeats every mesh period
    turns: int | None = 1

    def as_dict(self) -> dict:
        return dict(self.__dict__)

    def check(self, names: dict | None = None) -> RunSettings:
        """Raise DesignError naming the field (or ``names[field]``, e.g. the CLI's flag) whose value is out of bounds."""
        names = names or {}

        def bad(field, rule):
            raise DesignError(names.get(field, field), rule)

        for field, bound in BOUNDS.items():
            value = getattr(self, field)
            if value is not None and not bound.holds(value):
                rule = f"must be {bound.rule()}" + (" or 'full'" if field == "turns" else "")
                bad(field, f"{rule}, got {value:g}")
        return self


def _sections(drive, k: int) -> np.ndarray:
    """``k`` sections over the face width, and always both face ends (on a coned drive the
    worst section is usually an end, which a mid-face section alone misses)."""
    bw = drive.design.drive.face_width
    return np.unique(np.concatenate([drive.sections(k), [0.0, bw]]))


#: the CLI's flag of each RunSettings field, for its error lines
FLAGS = {
    "step_deg": "--step-deg",
    "sections": "--sections",
    "chord_tol_um": "--chord-tol-um",
    "turns": "--turns",
    "interference_tol_um": "--interference-tol-um",
}


def audit_settings(drive, rs: RunSettings, turns: int = 1) -> AuditSettings:
    """The engine's settings of a run: ``rs.step_deg`` over ``turns`` generator turns, ``rs.sections`` and both face ends."""
    n = int(round(360.0 / rs.step_deg))
    return AuditSettings(
        angles=np.deg2rad(np.arange(n * turns) * (360.0 / n)),
        sections=_sections(drive, rs.sections),
        use_period=rs.use_period,
        use_waves=rs.use_waves,
        use_mirror=rs.use_mirror,
        cull=rs.cull,
        bound=rs.bound,
        interference_tol=rs.interference_tol_um * 1e-3,
        refine=rs.refine,
    )


def run_audit(design_path, rs: RunSettings, progress=None):
    """Load, build and audit a design over a full generator revolution (an imperfect drive: ``rs.turns`` of them).

    Returns
    -------
    drive : wgcad.drive.Drive
    result : AuditResult
    """
    rs.check()
    design = load_design(design_path)
    n = int(round(360.0 / rs.step_deg))
    # judged before any large allocation: outlines, sample arrays and evaluation batches
    run = RunShape(
        angles=n,
        sections=rs.sections,
        use_period=rs.use_period,
        use_waves=rs.use_waves,
        use_mirror=rs.use_mirror,
        bound=rs.bound,
        exports=False,
    )
    # the imperfect poses (docs/models.md 6.2) take the rigid gear as the fixed member (the housing's
    # frame); with a fixed flexspline the audit stays on perfect parts and says so (cli.common.not_modelled)
    imperfect = design.imperfections.any and design.drive.fixed == "rigid"
    if imperfect:
        # imperfect parts: the sweep is held one chunk of generator angles at a time
        # (wgcad.clearance.imperfect), whatever its length
        run = replace(run, angles=min(n, chunk_angles(design.drive.z_flex, rs.sections)), use_period=False)
    turns = 1
    if imperfect:
        turns = full_cycle_turns(design.drive.z_flex, design.drive.z_rigid) if rs.turns is None else rs.turns
    elif rs.turns != 1:
        raise DesignError(
            "turns",
            "sweeps more generator turns only for an imperfect drive (an [imperfections] table, "
            "rigid gear fixed): a perfect drive repeats every mesh period",
        )
    drive = build_drive(design, tol=rs.chord_tol_um * 1e-3, max_memory_mb=rs.max_memory_mb, run=run)
    settings = audit_settings(drive, rs, turns)
    if imperfect:
        return drive, audit_imperfect(drive, settings, Imperfections.from_spec(design.imperfections), progress=progress)
    return drive, audit(drive, settings, progress=progress)
