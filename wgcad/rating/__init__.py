"""Rating a drive as a catalogue does: flexspline stress and fatigue, tooth-root concentration, stiffness fit, ratcheting, bearing life, and the datasheet that binds them (docs/models.md 10)."""

from wgcad.rating.datasheet import CRITERIA, Datasheet, ratcheting_torque, rate_drive

__all__ = ["CRITERIA", "Datasheet", "rate_drive", "ratcheting_torque"]
