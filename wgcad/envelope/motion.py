"""The motion of one flexspline tooth relative to the rigid gear, with its rate, in closed form (docs/models.md 13).

A motion maps the tooth frame (tooth centred on +x) into the rigid gear's
frame: ``X = R(rot(t)) p + shift(t)``; its rate is ``dX/dt = rot'(t) J R p +
shift'(t)`` (``J`` a quarter turn). The envelope (:mod:`wgcad.envelope.conjugate`)
needs only that.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wgcad.kinematics import flex_rotation

__all__ = ["LawMotion", "RotationMotion"]


@dataclass(frozen=True, slots=True)
class LawMotion:
    """Tooth 0 of a flexspline placed by a deformation law (docs/models.md 3.1) as the generator turns by ``t``
    (rad) in the rigid gear's frame, the rigid gear fixed: the tooth sits ``phi = t/u_hg - t`` from the major
    axis, and its pose is ``rot = t + phi + theta(phi)``, ``shift = R(t) origin(phi) - R(rot) (r_m, 0)`` with
    ``origin = (r_m + w) e_r(phi) + v e_t(phi)`` (:func:`wgcad.placement.tooth_pose`)."""

    law: object
    r_m: float
    z_flex: int
    z_rigid: int

    @property
    def dphi(self) -> float:
        """``dphi/dt``: the tooth's angle from the major axis per generator angle (``1/u_hg - 1``)."""
        return float(flex_rotation(1.0, self.z_flex, self.z_rigid)) - 1.0

    def phi(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        return flex_rotation(t, self.z_flex, self.z_rigid) - t

    def pose(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``rot (T,)``, ``shift (T, 2)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        phi = self.phi(t)
        st = self.law.state(phi)
        rot = t + phi + st.theta
        c, s = np.cos(phi), np.sin(phi)
        rad = self.r_m + st.w
        o = np.stack([rad * c - st.v * s, rad * s + st.v * c], axis=-1)
        ct, stt = np.cos(t), np.sin(t)
        shift = np.stack([ct * o[:, 0] - stt * o[:, 1], stt * o[:, 0] + ct * o[:, 1]], axis=-1)
        shift -= (self.r_m - self.law.tooth_offset) * np.stack([np.cos(rot), np.sin(rot)], axis=-1)
        return rot, shift

    def rate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``rot'(t) (T,)``, ``shift'(t) (T, 2)`` from the law's own derivatives (no differencing)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        phi = self.phi(t)
        st = self.law.state(phi)
        dp = self.dphi
        rot = t + phi + st.theta
        drot = 1.0 + dp * (1.0 + st.dtheta)
        c, s = np.cos(phi), np.sin(phi)
        rad = self.r_m + st.w
        o = np.stack([rad * c - st.v * s, rad * s + st.v * c], axis=-1)
        # d origin / d phi = (w' - v) e_r + (r_m + w + v') e_t
        a, b = st.dw - st.v, rad + st.dv
        do = dp * np.stack([a * c - b * s, a * s + b * c], axis=-1)
        ct, stt = np.cos(t), np.sin(t)
        # d/dt [R(t) o] = J R(t) o + R(t) do
        ro = np.stack([ct * o[:, 0] - stt * o[:, 1], stt * o[:, 0] + ct * o[:, 1]], axis=-1)
        rdo = np.stack([ct * do[:, 0] - stt * do[:, 1], stt * do[:, 0] + ct * do[:, 1]], axis=-1)
        dshift = np.stack([-ro[:, 1], ro[:, 0]], axis=-1) + rdo
        dshift -= (self.r_m - self.law.tooth_offset) * drot[:, None] * np.stack([-np.sin(rot), np.cos(rot)], axis=-1)
        return drot, dshift


@dataclass(frozen=True, slots=True)
class RotationMotion:
    """A gear of ``z1`` teeth turning about a fixed centre in mesh with a gear of ``z2`` (internal: ``z2 > z1``,
    same sense) whose centre is ``a`` away, seen from the second gear: ``rot = t (1 - z1/z2)``, ``shift =
    a e(-t z1/z2)`` (the tooth frame's origin is the first gear's centre). The envelope of an involute in this motion
    is the mating involute: the closed-form check of :mod:`wgcad.envelope.conjugate`."""

    a: float
    z1: int
    z2: int

    def pose(self, t) -> tuple[np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = self.z1 / self.z2
        u = -k * t
        return t * (1.0 - k), self.a * np.stack([np.cos(u), np.sin(u)], axis=-1)

    def rate(self, t) -> tuple[np.ndarray, np.ndarray]:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = self.z1 / self.z2
        u = -k * t
        return np.full_like(t, 1.0 - k), self.a * k * np.stack([np.sin(u), -np.cos(u)], axis=-1)
