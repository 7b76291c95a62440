"""The wind-up's hysteresis loop with friction in the tooth contacts, the generator held (docs/models.md 10.8).

Between two loaded states of rising torque every loaded tooth contact slides by the projection of its material
point's move (:func:`~wgcad.placement.sliding.material_shift`) on the contact's tangent; friction takes
``mu F |ds|`` of work (``F`` the mean of the two states' forces). Spread over the output's wind-up between them it is a
friction torque ``T_f = dE / dtheta`` at the output, which the load must overcome winding up and which holds the
drive back unwinding: the loading branch is ``T + T_f`` at the wind-up of ``T``, the unloading one ``T - T_f``
(rigid-plastic Coulomb contacts: every contact slides as soon as the kinematics asks it to). Negative torques
mirror the positive ones (symmetric teeth and law).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wgcad.placement.sliding import material_shift

__all__ = ["HysteresisLoop", "hysteresis_loop", "contact_slips"]


@dataclass(frozen=True, slots=True)
class HysteresisLoop:
    """The loop between ``-T_max`` and ``+T_max`` (N m, rad), on the states whose teeth carry load.

    Attributes
    ----------
    theta : (M,) float
        Wind-up of each state, rad (ascending).
    torque_nm : (M,) float
        Its (frictionless) torque.
    friction_nm : (M,) float
        The friction torque at the output there, N m: ``dE / dtheta`` of the intervals either side (their mean).
    work_nmm : (M - 1,) float
        The work friction takes over each interval between two states, N mm.
    """

    theta: np.ndarray
    torque_nm: np.ndarray
    friction_nm: np.ndarray
    work_nmm: np.ndarray

    @property
    def loading(self) -> np.ndarray:
        """Output torque of the loading branch at ``theta``, N m."""
        return self.torque_nm + self.friction_nm

    @property
    def unloading(self) -> np.ndarray:
        return self.torque_nm - self.friction_nm

    def branches(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The whole loop as drawn: ``(torque, wind-up)`` of the branch from ``-T_max`` up to ``+T_max``, then of the
        branch back down (N m, rad; the negative half mirrored)."""
        th, up, dn = self.theta, self.loading, self.unloading
        rising = (np.concatenate([-dn[::-1], up]), np.concatenate([-th[::-1], th]))
        falling = (np.concatenate([dn[::-1], -up]), np.concatenate([th[::-1], -th]))
        return rising[0], rising[1], falling[0], falling[1]

    @property
    def width_nm(self) -> float:
        """Largest torque between the branches, N m (0: the loop closes)."""
        return float(2.0 * self.friction_nm.max()) if self.friction_nm.size else 0.0

    @property
    def loss_j(self) -> float:
        """Energy one cycle ``-T_max -> T_max -> -T_max`` dissipates: the loop's area, J (each half of the loop
        traversed up and down)."""
        return float(4e-3 * self.work_nmm.sum())

    def unloading_theta(self, torque_nm: float) -> float:
        """Wind-up of the branch returning from ``+T_max`` where it passes ``torque_nm`` (>= 0), rad; below the first
        loaded state the branch goes on straight from its first two states (into the free play, where a drive with
        backlash is held by nothing)."""
        T, th = self.unloading, self.theta
        if len(T) < 2:
            return float(th[0]) if len(th) else 0.0
        above = np.nonzero(T > torque_nm)[0]
        j = max(int(above[0]) if above.size else len(T) - 1, 1)
        return float(th[j - 1] + (th[j] - th[j - 1]) * (torque_nm - T[j - 1]) / (T[j] - T[j - 1]))

    @property
    def hysteresis_loss(self) -> float:
        """The loop's width in wind-up at zero torque, rad: between the returns from ``+T_max`` and ``-T_max`` (the
        free play included, as a catalogue's hysteresis loss is measured)."""
        return 2.0 * self.unloading_theta(0.0)

    def lost_motion(self, torque_nm: float) -> float:
        """Wind-up between the returns from ``+-T_max`` at ``+-torque_nm``, rad (the widest reading of the
        catalogue's lost motion at a small torque)."""
        return 2.0 * self.unloading_theta(torque_nm)


def _loaded(c) -> dict:
    """``(section, tooth, flank) -> index`` of a state's loaded tooth contacts."""
    idx = np.nonzero((c["kind"] == 1) & (c["force"] > 0))[0]
    return {(int(c["section"][i]), int(c["tooth"][i]), int(c["flank"][i])): int(i) for i in idx}


def contact_slips(a, b) -> tuple[np.ndarray, np.ndarray]:
    """``(mean force N, slip mm)`` of every tooth contact loaded in state ``a`` or ``b``: the slip is the flexspline
    material point's move from ``a`` to ``b`` along the contact's tangent (the point and normal of the state that
    loads it, ``a``'s when both do)."""
    ca, cb = a.contacts, b.contacts
    la, lb = _loaded(ca), _loaded(cb)
    keys = sorted(set(la) | set(lb))
    if not keys:
        return np.zeros(0), np.zeros(0)
    rows = [(ca, la[k]) if k in la else (cb, lb[k]) for k in keys]
    F = 0.5 * np.array(
        [(ca["force"][la[k]] if k in la else 0.0) + (cb["force"][lb[k]] if k in lb else 0.0) for k in keys]
    )
    sec = np.array([k[0] for k in keys])
    phi = np.array([c["phi"][i] for c, i in rows])
    pt = np.array([c["point"][i] for c, i in rows])
    nm = np.array([c["normal"][i] for c, i in rows])
    slip = np.zeros(len(keys))
    r_m = a.model.drive.r_m
    for s in np.unique(sec):
        m = sec == s
        d = material_shift(a.laws[int(s)], b.laws[int(s)], phi[m], pt[m], r_m)
        slip[m] = -d[:, 0] * nm[m, 1] + d[:, 1] * nm[m, 0]
    return F, slip


def hysteresis_loop(states, mu: float) -> HysteresisLoop:
    """The loop of ``states`` (one drive, the generator held, ascending torques) with coefficient ``mu``; states
    before the first whose teeth carry load (the rim crossing its free play) are left out."""
    states = sorted(states, key=lambda s: s.torque_nm)
    loaded = [bool(((s.contacts["kind"] == 1) & (s.contacts["force"] > 0)).any()) for s in states]
    states = states[loaded.index(True) :] if any(loaded) else []
    T = np.array([s.torque_nm for s in states])
    th = np.array([s.wind_up for s in states])
    work = np.zeros(max(len(states) - 1, 0))
    per = np.zeros_like(work)
    for j in range(len(work)):
        F, slip = contact_slips(states[j], states[j + 1])
        work[j] = mu * float((F * np.abs(slip)).sum())
        dth = th[j + 1] - th[j]
        per[j] = 1e-3 * work[j] / dth if dth > 0 else 0.0
    if per.size:
        fr = np.concatenate([[per[0]], 0.5 * (per[1:] + per[:-1]), [per[-1]]])
    else:
        fr = np.zeros(len(states))
    return HysteresisLoop(th, T, fr, work)
