"""Tolerances and default settings, each with the reason for its value."""

__all__ = [
    "CHORD_TOL",
    "MIN_TIP_THICKNESS_COEF",
    "ROOT_SPACE_MIN_COEF",
    "NEWTON_TOL",
    "INTERFERENCE_TOL",
    "DUPLICATE_TOL",
]

#: Largest distance (mm) between a discretised outline and the exact curve.
#: 1 um is well below manufacturing tolerances of fine-module teeth (ISO 1328
#: grade 5 profile tolerance at m 0.8 is ~4 um) and keeps a 202-tooth gear at
#: a few ten thousand vertices.
CHORD_TOL = 1e-3

#: Smallest tip thickness, as a fraction of the module. 0.2 m is the usual
#: lower limit for through-hardened teeth (pointed teeth chip and wear fast).
MIN_TIP_THICKNESS_COEF = 0.2

#: Smallest arc width of the space (external) / tooth (internal) left at the
#: root circle between two fillets, as a fraction of the module. Zero means the
#: fillets may meet but not cross.
ROOT_SPACE_MIN_COEF = 0.0

#: Convergence of Newton iterations on angles and arc lengths (radians / mm).
#: Far below the 1 nm discretisation error of any outline.
NEWTON_TOL = 1e-13

#: Penetration (mm) reported as contact rather than interference. Equal to the
#: default chord tolerance: outlines are only known to within it, so a
#: smaller overlap is not a finding about the design.
INTERFERENCE_TOL = 1e-3

#: Consecutive vertices closer than this (mm) are one vertex. 1 pm is six
#: orders below the 1 um chord tolerance of outlines and far above the
#: ~1e-14 mm rounding noise of float64 coordinates near 100 mm, so it removes
#: exact and round-off duplicates and nothing else.
DUPLICATE_TOL = 1e-9
