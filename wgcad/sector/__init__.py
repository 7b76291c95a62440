"""Discrete-motion drive with a sectored rigid gear: motion law, sectored clearance sweep, tooth heights, audit (docs/models.md 2.3)."""

from .built import built_gear
from .heights import ClosedFormHeights, SimulatedHeights, closed_form_heights, listed_heights, simulated_heights
from .motion import MotionLaw, Phase, motion_law
from .scene import SectoredAudit, SectoredScene, SweepPairs, sectored_audit

__all__ = [
    "MotionLaw",
    "Phase",
    "motion_law",
    "ClosedFormHeights",
    "SimulatedHeights",
    "closed_form_heights",
    "simulated_heights",
    "listed_heights",
    "SectoredScene",
    "SweepPairs",
    "sectored_audit",
    "SectoredAudit",
    "built_gear",
]
