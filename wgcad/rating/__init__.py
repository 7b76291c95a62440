"""Rating a drive as a catalogue does: flexspline stress and fatigue, tooth-root concentration, stiffness fit, ratcheting, bearing life, and the datasheet that binds them (docs/models.md 10).

Called, the package is the library's rating: ``wgcad.rating(design)`` is :func:`wgcad.api.rating`.
"""

from wgcad import entry_module
from wgcad.rating.datasheet import CRITERIA, Datasheet, ratcheting_torque, rate_drive

__all__ = ["CRITERIA", "Datasheet", "rate_drive", "ratcheting_torque"]

entry_module(__name__)  # wgcad.rating(design): wgcad.api.rating
