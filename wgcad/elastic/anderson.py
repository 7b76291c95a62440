"""Anderson acceleration of a load state's re-linearisation: the next linearisation point from the last few solutions (docs/models.md 4.1)."""

from __future__ import annotations

import numpy as np

__all__ = ["Anderson", "ANDERSON_START"]

#: The acceleration starts once the teeth move less than this per pass, mm: before, contact sets change.
ANDERSON_START = 0.02
_LEVER = 2.0  # mm, a tooth's lever: weighs ring couples against forces in the acceleration's metric
_KREF = 1e5  # N/mm, a contact stiffness: weighs rim motions against forces there


class Anderson:
    """Anderson acceleration of the re-linearisation (type II, Walker & Ni 2011) on the ring loads and the members'
    motion.

    The next linearisation point is the affine combination of the last
    solutions that best cancels their residuals (solution minus
    linearisation point), so it balances the torque as each of them does.
    Forces weigh in N, couples per ``_LEVER`` mm, motions times ``_KREF``
    N/mm (a contact stiffness; rotations at the rim's radius): the
    least-squares metric only. The history is dropped when a step does not
    lower the residual (a change of contact set).
    """

    def __init__(self, r_m: float, depth: int, planes: int = 1):
        self.r_m, self.depth, self.planes = r_m, depth, planes
        w_rim = np.tile([_KREF, _KREF, _KREF * r_m], planes)
        self._w = np.concatenate([w_rim, np.full(2 * planes + 2, _KREF)])
        self.reset()

    def reset(self):
        self.X, self.G, self.last = [], [], np.inf

    def _vec(self, loads, motion):
        return np.concatenate([loads[:, :2].ravel(), loads[:, 2] / _LEVER, self._w * motion.vector()])

    def step(self, loads, motion, loads_new, motion_new, change):
        if self.depth == 0:
            return loads_new, motion_new
        if change > self.last or change > ANDERSON_START:
            self.reset()
            if change > ANDERSON_START:
                return loads_new, motion_new
        self.last = change
        self.X.append(self._vec(loads, motion))
        self.G.append(self._vec(loads_new, motion_new))
        self.X, self.G = self.X[-(self.depth + 1) :], self.G[-(self.depth + 1) :]
        if len(self.X) < 2:
            return loads_new, motion_new
        R = [g - x for g, x in zip(self.G, self.X)]
        dR = np.stack([R[i + 1] - R[i] for i in range(len(R) - 1)], axis=1)
        dG = np.stack([self.G[i + 1] - self.G[i] for i in range(len(R) - 1)], axis=1)
        gamma, *_ = np.linalg.lstsq(dR, R[-1], rcond=1e-10)
        y = self.G[-1] - dG @ gamma
        n = len(loads)
        out = np.empty_like(loads)
        out[:, 0], out[:, 1] = y[: 2 * n].reshape(n, 2).T
        out[:, 2] = y[2 * n : 3 * n] * _LEVER
        return out, type(motion).from_vector(y[3 * n :] / self._w, self.planes)
