"""An imperfect drive's errors as the load model's inputs at a whole mesh period: each flexspline tooth's turn and move
against the rigid teeth, and the cam offset in the generator's frame (docs/models.md 6.3)."""

from __future__ import annotations

from math import pi

import numpy as np

from ..kinematics import gear_ratios
from ..placement.imperfect import Imperfections, cam_offset, flex_deviations, rigid_translation

__all__ = ["tooth_errors"]


def tooth_errors(model, imp: Imperfections, n: int):
    """The errors of the drive at ``n`` mesh periods as the model's inputs: ``(turn, move)`` per tooth and the cam offset.

    Returns
    -------
    (turn (S z_g,), move (S z_g, 2)), cam_offset_um, cam_offset_deg
    """
    drive = model.drive
    d = drive.design.drive
    z_g, z_b = d.z_flex, d.z_rigid
    sigma = 1 if d.rotation == "ccw" else -1
    phi_h = sigma * n * 2.0 * pi / z_b
    phi_g = phi_h / gear_ratios(z_g, z_b)["u_hg"]
    q = np.arange(z_g)
    k = (q + sigma * n) % z_g  # the drive's tooth at the model's position q
    dalpha, drho = flex_deviations(imp, k, z_g, drive.flex.r)
    ang = model.tables.angles[:z_g]  # the model's tooth angles (generator frame)
    # the rigid tooth facing each flexspline tooth: its run-out turn, read continuously along the gear
    # (exact at tooth centres; adjacent teeth differ by F_b/(2 r_b) 2 pi/z_b, far below a micrometre)
    a_rigid = ang + phi_h
    dev = (0.5 * imp.rigid_runout / drive.rigid.r) * np.sin(a_rigid - imp.rigid_install + imp.rigid_runout_phase)
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    T = rigid_translation(imp)
    T = np.array([c * T[0] - s * T[1], s * T[0] + c * T[1]])  # the rigid gear's shift in the generator frame
    turn = dalpha - dev
    # the tooth's axis after the turn: drho along it (the rim's own rotation there is theta, ~1e-2 rad: its
    # effect on a micrometre-sized drho is far below the figures)
    axis = np.stack([np.cos(ang + turn), np.sin(ang + turn)], axis=-1)
    move = drho[:, None] * axis - T[None, :]
    S = len(model.zs)
    E = cam_offset(imp, phi_h, phi_g)
    Eg = np.array([c * E[0] - s * E[1], s * E[0] + c * E[1]])
    return (
        (np.tile(turn, S), np.tile(move, (S, 1))),
        1e3 * float(np.hypot(*Eg)),
        float(np.degrees(np.arctan2(Eg[1], Eg[0]))),
    )
