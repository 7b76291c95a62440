"""Tolerances and default settings, each with the reason for its value."""

__all__ = [
    "CHORD_TOL",
    "MIN_TIP_THICKNESS_COEF",
    "ROOT_SPACE_MIN_COEF",
    "NEWTON_TOL",
    "INTERFERENCE_TOL",
    "DUPLICATE_TOL",
    "MIN_VERTEX_SPACING",
    "REFINE_TOL",
    "MAX_LOAD_LEVELS",
    "MAX_GENERATOR_ANGLES",
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

#: Smallest distance (mm) between neighbouring vertices of any outline wgcad
#: builds (rigid, deformed, exported). 0.1 um: more than ten times the float32
#: resolution of an STL coordinate up to ~800 mm from the axis (2^-24 * 800 mm
#: = 0.05 um), so no two vertices of an outline merge in a float32 file, and
#: well below the spacing of chords at any sensible chord tolerance
#: (``sqrt(8 R tol)`` is 7 um for a 0.2 mm fillet at 0.03 um); dropping a
#: vertex closer than this to its neighbour moves the polygon by far less than
#: the chord tolerance (the two chords it joins are nearly collinear).
MIN_VERTEX_SPACING = 1e-4

#: Tolerance (mm) to which the clearance engine's figures (minimum clearance,
#: penetration depth, entry gap, pinch) are refined on the exact tooth curves,
#: whatever the chord tolerance: 1 nm, a thousandth of the default 1 um chords
#: and ten times below the 0.01 um accuracy the audit promises.
REFINE_TOL = 1e-6

#: Most torque levels one ``--torque-nm`` takes (``wgcad audit``, ``wgcad ke``). 1000 levels resolve a stiffness or
#: entry-gap curve to 0.1 % of its torque range, finer than its figure's pixels and its table's lines need; they
#: are a thousand elastic solves and ~1.3 GB of solved states for D1 at 3 sections, inside the
#: default memory budget (wgcad.design.budget: the memory estimate judges each run's levels too).
MAX_LOAD_LEVELS = 1000

#: Most generator angles one ``--generator-angle`` takes (``wgcad generate``, ``wgcad parts``): one deformed-state
#: drawing per degree of a revolution. Each angle writes its own DXF and PNG (~0.8 MB of files for D1), so
#: 360 are already ~0.3 GB; memory grows ~1 MB an angle (peak RSS of ``generate`` D1 --no-stl: 129 MB
#: at 11 angles, 139 MB at 21), so these stay well inside the default memory budget without an estimate of their own.
MAX_GENERATOR_ANGLES = 360
