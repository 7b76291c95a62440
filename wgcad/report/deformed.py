"""The deformed drive at one generator angle as the data of ``wgcad generate``'s drawing and picture (docs/models.md 3).

The outlines come from :func:`wgcad.placement.deformed.deformed_state`;
this adds what the picture needs to frame them: how far the tips still
overlap the rigid tip circle toward the minor axis (the close-up's extent)
and the radial window of the teeth.
"""

from __future__ import annotations

import numpy as np

from ..placement.deformed import deformed_state, rim_samples

__all__ = ["deformed_scene"]


def deformed_scene(drive, phi_h_abs: float, imp=None) -> dict:
    """Geometry of the deformed drive at generator angle ``phi_h_abs`` (rad, relative to the fixed member), for drawing.

    With ``imp`` (:class:`wgcad.placement.imperfect.Imperfections`, rigid gear
    fixed) every tooth of both gears sits where its errors put it, and the
    rim and neutral line move with the cam offset (docs/models.md 6.2).
    """
    d = drive.design.drive
    st = deformed_state(drive, phi_h_abs, drive.tol, imp=imp)
    teeth, phi = st.flex_teeth, st.flex_phi
    # how far toward the minor axis the tips still overlap the rigid tip circle (close-up extent)
    R = np.hypot(teeth[..., 0], teeth[..., 1])
    over = (R.min(axis=1) < drive.rigid.r_a) if drive.external else (R.max(axis=1) > drive.rigid.r_a)
    phw = (phi + np.pi) % (2 * np.pi) - np.pi
    side = phw * (1.0 if d.rotation == "ccw" else -1.0)
    reach = side[over & (side >= 0) & (side <= np.pi / d.waves)]
    entry_deg = float(np.rad2deg(reach.max())) + 4.0 if reach.size else 45.0
    w = drive.law.state(rim_samples(drive, drive.tol)).w
    return {
        "flex_teeth": teeth,
        "flex_phi": phi,
        "flex_outline": st.flex_outline,
        "entry_deg": min(entry_deg, 180.0 / d.waves),
        "neutral_phi": st.neutral_phi,
        "neutral_w": w,
        "r_m": drive.r_m,
        "waves": d.waves,
        "w0": drive.law.w0,
        "flex_rim": st.rim,
        "neutral": st.neutral,
        "rigid_outline": st.rigid_outline,
        "imperfect": imp is not None,
        "rigid_rim_radius": drive.rigid_rim_radius,
        "major_axis": st.phi_h + st.frame,
        "entry_sign": 1.0 if d.rotation == "ccw" else -1.0,
        "r_ref": drive.rigid.r,
        "module": d.module,
        "rigid_outward": not drive.external,
        # radial window of the close-up: both gears' teeth, the flexspline's moved by up to +-1.2 W0
        "y_range": (
            min(
                drive.rigid.r_a,
                drive.rigid.r_f,
                drive.flex.r_a - 1.2 * drive.law.w0,
                drive.flex.r_f - 1.2 * drive.law.w0,
            )
            - drive.rigid.r
            - 0.2 * d.module,
            max(
                drive.rigid.r_a,
                drive.rigid.r_f,
                drive.flex.r_a + 1.2 * drive.law.w0,
                drive.flex.r_f + 1.2 * drive.law.w0,
            )
            - drive.rigid.r
            + 0.2 * d.module,
        ),
    }
