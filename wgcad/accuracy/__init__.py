"""Accuracy of imperfect drives: flank-error model (docs/models.md 6)."""

from wgcad.accuracy.flank_errors import (
    ENGAGEMENTS,
    Eccentricities,
    FlankErrors,
    flank_error_table,
    flank_errors,
    flank_errors_over_rotation,
    gear_angles,
    write_flank_error_csv,
)

__all__ = [
    "ENGAGEMENTS",
    "Eccentricities",
    "FlankErrors",
    "gear_angles",
    "flank_errors",
    "flank_errors_over_rotation",
    "flank_error_table",
    "write_flank_error_csv",
]
