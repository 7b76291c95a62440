"""The deformed drive at one generator angle, as outlines: placed teeth, rim, neutral line, rigid gear (docs/models.md 3).

One construction for every consumer of the deformed state: ``wgcad
generate``'s drawing and picture per ``--generator-angle``
(:mod:`wgcad.report.deformed`) and the part set's deformed assembly
(:mod:`wgcad.export.parts.assembly`). Angles are relative to the fixed
member: with the flexspline fixed, the rigid gear turns by ``phi / u_hb``
and everything is drawn in the flexspline's frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ..errors import GeometryError
from ..kinematics import gear_ratios
from .imperfect import cam_offset, flex_poses, rigid_poses
from .law import deformed_curve, join_teeth, place_flex_teeth, tooth_angles, transform

__all__ = ["DeformedState", "deformed_state", "generator_frame", "rim_samples", "rotate"]


def rotate(p: np.ndarray, a: float) -> np.ndarray:
    """Points ``(..., 2)`` turned by ``a`` (rad) about the origin."""
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1]], axis=-1)


def generator_frame(drive, phi_abs: float) -> tuple[float, float]:
    """``(phi_h, frame)``: the generator angle relative to the flexspline and the drawing frame's turn (rad).

    Rigid gear fixed: ``(phi_abs, 0)``. Flexspline fixed: the rigid gear has
    turned by ``phi_abs / u_hb`` and the picture is drawn in the flexspline's
    frame, which that turn moves.
    """
    d = drive.design.drive
    if d.fixed == "rigid":
        return phi_abs, 0.0
    phi_b = phi_abs / gear_ratios(d.z_flex, d.z_rigid)["u_hb"]
    return phi_abs - phi_b, phi_b


def rim_samples(drive, tol: float) -> np.ndarray:
    """Angles at which a deformed rim is drawn: its chords within ``tol`` of the curve (at least 720)."""
    n = max(720, int(np.ceil(2 * np.pi / np.sqrt(8 * tol / drive.r_m))))
    return np.linspace(0.0, 2 * np.pi, n, endpoint=False)


@dataclass(frozen=True, slots=True)
class DeformedState:
    """Outlines (mm, the fixed member's frame) of the drive at one generator angle."""

    phi_h: float  # generator angle relative to the flexspline, rad
    frame: float  # turn of the drawing frame (flexspline fixed), rad
    flex_teeth: np.ndarray  # (z_g, n, 2) placed tooth periods
    flex_phi: np.ndarray  # (z_g,) tooth angles
    flex_outline: np.ndarray  # joined outline of the placed teeth
    rim: np.ndarray  # the flexspline's bore (internal deformation) or outer rim, deformed
    neutral: np.ndarray  # the neutral line
    neutral_phi: np.ndarray  # angles of the neutral line's samples (frame included)
    rigid_outline: np.ndarray  # the rigid gear's outline (its teeth posed with their errors if given)


def deformed_state(drive, phi_abs: float, tol: float, z: float | None = None, imp=None) -> DeformedState:
    """The deformed drive at generator angle ``phi_abs`` (rad, counter-clockwise, relative to the fixed member).

    ``z``: the axial section of a coned flexspline (None: the law of the
    drive, its centre section). ``imp``
    (:class:`wgcad.placement.imperfect.Imperfections`, rigid gear fixed):
    every tooth of both gears sits where its errors put it, and the rim and
    neutral line move with the cam offset (docs/models.md 6.2). Raises
    GeometryError when the placed teeth's outline crosses itself.
    """
    phi_h, frame = generator_frame(drive, phi_abs)
    d = drive.design.drive
    _, phi = tooth_angles(d.z_flex, d.z_rigid, phi_h)
    law = drive.law_at(z) if (z is not None and drive.coned) else drive.law
    if imp is not None:
        teeth = transform(drive.flex.period, *flex_poses(drive, imp, phi_h, z=z))
        rigid_outline = join_teeth(transform(drive.rigid.period, *rigid_poses(drive, imp)))
        offset = cam_offset(imp, phi_h, phi_h / gear_ratios(d.z_flex, d.z_rigid)["u_hg"])
    else:
        teeth = place_flex_teeth(drive, phi_h, local=drive.flex.period, z=z if drive.coned else None)
        rigid_outline, offset = drive.rigid.outline, np.zeros(2)
    teeth = rotate(teeth, frame)
    outline = join_teeth(teeth)
    if not shapely.LinearRing(outline).is_simple:
        at = f", z = {z:.3f} mm" if z is not None else ""
        raise GeometryError(
            f"deformed flexspline outline at generator angle {np.rad2deg(phi_abs):g} deg{at} is not simple"
        )
    ph = rim_samples(drive, tol)
    rim = deformed_curve(law, drive.r_m, drive.flex_rim_radius - drive.r_m, ph)
    neutral = deformed_curve(law, drive.r_m, 0.0, ph)
    return DeformedState(
        phi_h=phi_h,
        frame=frame,
        flex_teeth=teeth,
        flex_phi=phi,
        flex_outline=outline,
        rim=rotate(rotate(rim, phi_h), frame) + offset,
        neutral=rotate(rotate(neutral, phi_h), frame) + offset,
        neutral_phi=ph + phi_h + frame,
        rigid_outline=rotate(rigid_outline, frame),
    )
