"""Flexspline deformation: neutral-line laws (docs/models.md 3) and coning along the axis."""

from wgcad.deformation.coning import coned_w0
from wgcad.deformation.laws import (
    LAWS,
    Disc,
    Ellipse,
    ExternalRing,
    FourForce,
    Harmonic,
    Law,
    RimState,
    make_law,
)

__all__ = [
    "RimState",
    "Law",
    "Harmonic",
    "Disc",
    "FourForce",
    "Ellipse",
    "ExternalRing",
    "LAWS",
    "make_law",
    "coned_w0",
]
