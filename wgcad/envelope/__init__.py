"""Conjugate teeth: the envelope of a flexspline tooth's flank in its motion relative to the rigid gear (docs/models.md 13)."""

from wgcad.envelope.conjugate import EnvelopePoints, envelope, flank_pieces
from wgcad.envelope.motion import LawMotion, RotationMotion

__all__ = ["EnvelopePoints", "envelope", "flank_pieces", "LawMotion", "RotationMotion"]
