"""Coulomb friction in the tooth contacts of one loaded state: each contact's normal force (elastic model) times its
sliding speed (placement kinematics) times the coefficient, the friction forces' moment on the output and the
share of the loss the generator supplies directly (docs/models.md 10.8)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wgcad.placement.sliding import sliding_rate

__all__ = ["ToothFriction", "tooth_friction", "generator_direction", "flex_rate"]


@dataclass(frozen=True, slots=True)
class ToothFriction:
    """The tooth contacts' friction of one state (N, mm, per generator radian).

    Attributes
    ----------
    force : (K,) float
        Normal force of every tooth contact of the state, N.
    slide : (K,) float
        Sliding speed of the flexspline tooth against the rigid tooth along the contact, mm per generator radian
        (signed along ``J n``, the generator turning the way the drive runs).
    loss : float
        ``mu sum F |slide|``: the work friction takes per generator radian, N mm (the input torque it costs).
    output_moment : float
        Moment of the friction forces about the axis on the flexspline, N mm, positive when it adds to the output's
        load (its share of the input torque is ``output_moment / |u_hg|``).
    generator_moment : float
        The rest of ``loss``, N mm: what the generator supplies directly through the rim's deformation wave.
    """

    force: np.ndarray
    slide: np.ndarray
    loss: float
    output_moment: float
    generator_moment: float


def generator_direction(model) -> float:
    """+1 when the generator turns counter-clockwise as the drive runs: the flexspline moves against its load torque
    (``model.torque_sign``) and turns ``1/u_hg`` of the generator."""
    u = float(model.scene.ratios["u_hg"])
    return float(-model.torque_sign * np.sign(u))


def flex_rate(model) -> float:
    """``1/u_hg - 1``: the flexspline's material angle per generator radian in the generator's frame."""
    return 1.0 / float(model.scene.ratios["u_hg"]) - 1.0


def tooth_friction(state, mu: float) -> ToothFriction:
    """Friction of every tooth contact of the loaded ``state`` with Coulomb coefficient ``mu``.

    The state's rim (each section's loaded law) keeps its shape in the generator's frame over the mesh period the
    state stands for; the flexspline's material flows through it (docs/models.md 10.8), so a contact's sliding
    speed is the placement's rate (:func:`~wgcad.placement.sliding.sliding_rate`). First order in ``mu``: the
    normal forces are the frictionless model's.
    """
    model = state.model
    c = state.contacts
    t = np.nonzero((c["kind"] == 1) & (c["force"] > 0))[0]
    r_m = model.drive.r_m
    rate = flex_rate(model)
    s_h = generator_direction(model)
    slide = np.zeros(len(t))
    for sec in np.unique(c["section"][t]):
        m = c["section"][t] == sec
        k = t[m]
        v, _ = sliding_rate(state.laws[int(sec)], c["phi"][k], c["point"][k], c["normal"][k], r_m, rate)
        slide[m] = s_h * v
    F = c["force"][t]
    loss = float(mu * (F * np.abs(slide)).sum())
    # the friction force on the flexspline tooth opposes its sliding: -mu F sign(slide) J n
    n = c["normal"][t]
    tang = np.stack([-n[:, 1], n[:, 0]], axis=-1)
    f = -(mu * F * np.sign(slide))[:, None] * tang
    p = c["point"][t]
    m_f = float((p[:, 0] * f[:, 1] - p[:, 1] * f[:, 0]).sum())
    out = float(model.torque_sign * m_f)
    u = abs(float(model.scene.ratios["u_hg"]))
    return ToothFriction(F, slide, loss, out, loss - out / u)
