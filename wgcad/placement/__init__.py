"""Tooth poses: every flexspline tooth moved as a rigid body with its rim cross-section (docs/models.md 3).

``law``: poses from a deformation law (the perfect drive), outlines joined
from placed teeth; ``imperfect``: the poses of imperfect parts (run-out,
eccentricities, cam mounting errors, installation angles, docs/models.md
6.2). Loaded poses come from the elastic model's states as laws
(``wgcad.elastic.LoadedLaw``).
"""

from .law import (
    deformed_curve,
    join_teeth,
    place_flex_teeth,
    place_points,
    place_points_first_order,
    pose_from_displacements,
    tooth_angles,
    tooth_frames,
    tooth_pose,
    transform,
)
from .sliding import material_shift, sliding_rate

__all__ = [
    "tooth_angles",
    "tooth_frames",
    "transform",
    "pose_from_displacements",
    "tooth_pose",
    "place_points",
    "place_points_first_order",
    "place_flex_teeth",
    "deformed_curve",
    "join_teeth",
    "sliding_rate",
    "material_shift",
]
