"""Design file -> drive -> clearance audit, with the settings a run (or a baseline) names."""

from __future__ import annotations

import numpy as np

from .arrays import unique_sorted
from .clearance.engine import AuditSettings, audit
from .design import load_design
from .design.budget import DEFAULT_MAX_MEMORY_MB
from .drive import build_drive
from .errors import DesignError
from .records import record

__all__ = ["RunSettings", "run_audit"]


@record(frozen=True)
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
    refine: bool = True  # figures on the exact tooth curves (issue 8)
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

        if not 1e-4 <= self.step_deg <= 90.0:
            bad("step_deg", f"must be in [1e-4, 90] degrees, got {self.step_deg:g}")
        if not 1 <= self.sections <= 200:
            bad("sections", f"must be 1..200, got {self.sections}")
        if not 0.0 < self.chord_tol_um <= 100.0:
            bad("chord_tol_um", f"must be in (0, 100] um, got {self.chord_tol_um:g}")
        if self.turns is not None and not 1 <= self.turns <= 10_000:
            bad("turns", f"must be 1..10000 generator turns or 'full', got {self.turns}")
        if not 0.0 <= self.interference_tol_um <= 1000.0:
            bad("interference_tol_um", f"must be in [0, 1000] um, got {self.interference_tol_um:g}")
        return self


def _sections(drive, k: int) -> np.ndarray:
    """``k`` sections over the face width, and always both face ends (issue 13: ``--sections 1``
    checked only mid-face, -14.6 um where the open end was at -58.8 um)."""
    bw = drive.design.drive.face_width
    return unique_sorted(np.concatenate([drive.sections(k), [0.0, bw]]))


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
    run = {
        "angles": n,
        "sections": rs.sections,
        "use_period": rs.use_period,
        "use_waves": rs.use_waves,
        "use_mirror": rs.use_mirror,
        "bound": rs.bound,
        "exports": False,
    }
    # the imperfect poses (docs/models.md 6.2) take the rigid gear as the fixed member (the housing's
    # frame); with a fixed flexspline the audit stays on perfect parts and says so (cli.common.not_modelled)
    imperfect = design.imperfections.any and design.drive.fixed == "rigid"
    if imperfect:
        # imperfect parts: the sweep is held one chunk of generator angles at a time
        # (wgcad.clearance.imperfect), whatever its length
        from .clearance.imperfect import chunk_angles

        run.update(angles=min(n, chunk_angles(design.drive.z_flex, rs.sections)), use_period=False)
    turns = 1
    if imperfect:
        from .placement.imperfect import full_cycle_turns

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
        from .clearance.imperfect import audit_imperfect
        from .placement.imperfect import Imperfections

        return drive, audit_imperfect(drive, settings, Imperfections.from_spec(design.imperfections), progress=progress)
    return drive, audit(drive, settings, progress=progress)
