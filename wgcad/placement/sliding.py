"""How a flexspline tooth slides on its mate: the rate of its material point at a contact as the generator turns, and
its displacement between two states of the rim (docs/models.md 10.8).

Both are kinematics of the placement (docs/models.md 3.1): a tooth at material angle ``phi`` from the major axis
moves as a rigid body with its rim cross-section, origin ``o(phi) = (r_m + w) e_r + v e_t`` turned by ``phi +
theta(phi)``. In the generator's frame a quasi-static rim keeps its shape while the flexspline's material flows
through it at ``dphi/dt = 1/u_hg - 1`` per generator radian (``t``, relative to the rigid gear) and the rigid gear
turns at ``-1``; the relative velocity of the two bodies at a point ``P`` is

    v = dphi/dt [o'(phi) + (1 + theta'(phi)) J (P - o)] + J P        (J: a quarter turn)

whose component along the contact's tangent is the sliding speed, mm per generator radian.
"""

from __future__ import annotations

import numpy as np

from .law import tooth_pose

__all__ = ["sliding_rate", "material_shift"]


def _quarter(a: np.ndarray) -> np.ndarray:
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def sliding_rate(law, phi, point, normal, r_m: float, dphi_dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The flexspline tooth's velocity against the rigid gear at each contact, split along the contact.

    Parameters
    ----------
    law : Law
        The rim (nominal or loaded) the teeth ride on, generator frame.
    phi : (K,) float
        Material angle of each contact's tooth from the major axis, rad.
    point, normal : (K, 2) float
        Contact point on the flexspline tooth and its unit normal, generator frame (mm).
    r_m : float
        Neutral-line radius, mm.
    dphi_dt : float
        ``1/u_hg - 1``: the flexspline's material angle per generator radian in the generator frame.

    Returns
    -------
    slide : (K,) float
        Velocity along the tangent ``J n``, mm per generator radian (signed).
    approach : (K,) float
        Velocity along the normal (zero for conjugate flanks, the rate a non-conjugate pair closes or opens).
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    P = np.atleast_2d(np.asarray(point, dtype=float))
    n = np.atleast_2d(np.asarray(normal, dtype=float))
    st = law.state(phi)
    c, s = np.cos(phi), np.sin(phi)
    rad = r_m + st.w
    o = np.stack([rad * c - st.v * s, rad * s + st.v * c], axis=-1)
    a, b = st.dw - st.v, rad + st.dv  # d o / d phi = (w' - v) e_r + (r_m + w + v') e_t
    do = np.stack([a * c - b * s, a * s + b * c], axis=-1)
    vel = dphi_dt * (do + (1.0 + st.dtheta)[:, None] * _quarter(P - o)) + _quarter(P)
    return (vel * _quarter(n)).sum(axis=1), (vel * n).sum(axis=1)


def material_shift(law_from, law_to, phi, point, r_m: float) -> np.ndarray:
    """Where the flexspline material point at ``point`` (on the tooth at ``phi``, rim ``law_from``) goes when the rim
    becomes ``law_to``, as a displacement ``(K, 2)``, mm (the rigid gear still: the laws hold the rim's motion
    against it)."""
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    P = np.atleast_2d(np.asarray(point, dtype=float))
    r0, s0 = tooth_pose(law_from, phi, r_m)
    r1, s1 = tooth_pose(law_to, phi, r_m)
    d = P - s0
    c, s = np.cos(r1 - r0), np.sin(r1 - r0)
    moved = np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], axis=-1) + s1
    return moved - P
