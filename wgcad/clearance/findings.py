"""What an audit found, as data: one typed record per figure (docs/models.md 5).

The engine fills these records in the units it computes in (mm, rad) and
says how each figure was obtained; the report layer
(:mod:`wgcad.report.audit`) rounds, converts to the units in the key names
and words them for people. Nothing here formats text.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Finding", "FIGURES", "METHODS", "AuditRun", "ImperfectRun"]

#: the figures an audit reports
FIGURES = ("min_clearance", "entry_gap", "entry_crossing", "entry_pinch", "backlash")

#: how a figure was obtained
METHODS = {
    "exact": "refined on the exact tooth curves (docs/models.md 5), to wgcad.constants.REFINE_TOL",
    "polygon": "measured on the outlines sampled at the chord tolerance: within 2 chord tolerances of the exact figure",
    "brent": "contact rotation found by Brent's method on the outlines (docs/models.md 5, backlash)",
}


@dataclass(frozen=True, slots=True)
class Finding:
    """One figure of an audit and where it lies.

    Attributes
    ----------
    figure : str
        One of :data:`FIGURES`.
    value : float
        mm for clearances and gaps (negative: penetration depth), rad for
        backlash; ``nan`` when the figure does not exist on this drive (the
        tips never cross the rigid tip circle, the teeth interfere so there
        is no dead travel, no pinch after the entry); backlash ``inf`` when
        no tooth engages at that generator angle (unbounded dead travel).
    method : str
        A key of :data:`METHODS`.
    tooth_angle : float or None
        The tooth's angle from the nearest major axis, rad (for the worst
        spot folded to ``>= 0``, with :attr:`mirror` the spot at ``-phi``).
    section_z : float or None
        Cross-section along the face width, mm (None: one section, no coning).
    location : str or None
        Where on the flexspline tooth: ``tip``, ``root``, ``working flank``,
        ``non-working flank``.
    generator_angle : float or None
        A generator angle at which a tooth is there, rad.
    tooth : int or None
        That tooth's index.
    polygon_value : float or None
        The same figure on the sampled outlines (before refinement).
    details : dict
        Figure-specific extras in internal units (e.g. ``overlap_area``
        mm^2, ``mirror`` = (tooth_angle, location), ``tip_to_tip_risk``).
    """

    figure: str
    value: float
    method: str
    tooth_angle: float | None = None
    section_z: float | None = None
    location: str | None = None
    generator_angle: float | None = None
    tooth: int | None = None
    polygon_value: float | None = None
    details: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.figure not in FIGURES:
            raise ValueError(f"unknown figure {self.figure!r}")
        if self.method not in METHODS:
            raise ValueError(f"unknown method {self.method!r}")


@dataclass(frozen=True, slots=True)
class ImperfectRun:
    """How an imperfect drive's audit swept (:func:`wgcad.clearance.imperfect.audit_imperfect`): the generator turns
    swept and the whole error cycle's, which work-skipping facts still hold (and why), the generator angles per
    chunk."""

    generator_turns: float
    full_cycle_turns: int
    shortcuts_that_hold: dict
    why: str
    chunk: int


@dataclass(frozen=True, slots=True)
class AuditRun:
    """What an audit ran with, in mm and rad (the report states it in the units of its keys, with its notes).

    ``angles``: the generator angles; ``sections``: the cross-sections, mm (``(None,)`` without coning);
    the shortcuts used; ``refined`` (figures on the exact curves) and ``chord_tol`` (the outlines' chord
    tolerance, mm); the working flank, the entry side (+1: entry at +phi), the rigid gear's pitch radius (mm);
    ``imperfect`` for an imperfect drive's audit."""

    angles: np.ndarray
    sections: tuple
    coned: bool
    face_width: float
    mesh_period: bool
    identical_waves: bool
    mirror_symmetry: bool
    culling: bool
    branch_and_bound: bool
    refined: bool
    chord_tol: float
    working_flank: str
    entry_sign: int
    rigid_pitch_radius: float
    imperfect: ImperfectRun | None = None

    @property
    def face_ends_checked(self) -> bool:
        """Both ends of the face were among the sections (always, without coning)."""
        if not self.coned:
            return True
        return min(self.sections) <= 1e-9 and max(self.sections) >= self.face_width - 1e-9
