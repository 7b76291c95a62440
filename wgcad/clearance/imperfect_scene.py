"""The imperfect drive's scene: the rigid teeth with the rigid gear's run-out, in the frame of the rigid gear's own centre (docs/models.md 6.2, 7)."""

from __future__ import annotations

import numpy as np
import shapely

from ..placement import transform
from ..placement.imperfect import Imperfections, rigid_poses, rigid_translation
from .scene import Scene

__all__ = ["ImperfectScene"]


class ImperfectScene(Scene):
    """A :class:`Scene` whose rigid teeth carry the rigid gear's run-out, in the frame of the rigid gear's own centre.

    Built from a perfect scene (templates and exact curves are shared). The
    rigid gear's eccentric shift ``T`` is taken out of the frame: the rigid
    teeth stay about the origin (turned by their run-out) and flexspline
    poses are given relative to the rigid centre (:meth:`relative`), so the
    perfect scene's neighbour search and third-tooth bound, which measure
    angles about the origin, hold as they are. Run-out turns a tooth by at
    most ``F_b / (2 r_b)``, far below half a pitch, so the bracketing teeth
    stay the bracketing teeth.
    """

    @classmethod
    def from_scene(cls, scene: Scene, imp: Imperfections) -> ImperfectScene:
        new = cls.__new__(cls)
        new.__dict__.update(scene.__dict__)
        new.imp = imp
        new.center_b = rigid_translation(imp)
        rot, shift = rigid_poses(scene.drive, imp)
        new.rigid_rot, new.rigid_shift = rot, shift - new.center_b  # zero: the frame of the rigid centre
        new.rigid_pts = transform(scene.rigid.local, rot, new.rigid_shift)
        new.rigid_pts.setflags(write=False)
        new.rigid_geoms = shapely.polygons(new.rigid_pts)
        shapely.prepare(new.rigid_geoms)
        return new

    def relative(self, shift: np.ndarray) -> np.ndarray:
        """Flexspline shifts (rigid-gear frame) in the frame of the rigid gear's own centre."""
        return shift - self.center_b
