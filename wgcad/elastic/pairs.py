"""Tooth pairs of a load state measured on the exact geometry and kept, linearised, between re-linearisations (docs/models.md 4.1)."""

from __future__ import annotations

import numpy as np

from .teeth import pair_contacts

__all__ = ["MeasuredPairs", "GAP_MARGIN", "REFRESH_MARGIN"]

#: Flank pairs farther apart than this are left out of the contact problem, mm
#: (checked again at every re-linearisation on the loaded geometry, so a pair
#: enters as soon as the rim brings it this close).
GAP_MARGIN = 0.1
#: A pair is measured again when its linearised gap is below twice its tooth's motion since the last
#: measurement plus this, mm (0.5 um). The margin absorbs what the Lipschitz bound leaves out: the
#: linearisation turns the tooth by theta to first order (its second-order error, lever * dtheta^2 / 2,
#: stays below 0.01 um for the milliradians of a load state) and round-off.
REFRESH_MARGIN = 5e-4
#: Pairs the final report measures first when none open has been measured at the solved poses (then the
#: smallest open gap found bounds which others can be nearer).
_FIRST_OPEN = 4


class MeasuredPairs:
    """The linearised contacts of every tooth pair (key ``(section z_g + tooth) 2 + flank``), kept between passes.

    A pair is measured again on the exact geometry (the clearance engine)
    when it is new, or when it could be closing: its linearised gap is less
    than twice the largest distance any point of its tooth has moved since it
    was measured, plus REFRESH_MARGIN. Gaps and their linearisations are both
    1-Lipschitz in the tooth's motion, so a pair that is not measured again
    is open on the exact geometry too: it carries no force and the contact
    solution is the one full re-measurement gives (the same iterates).

    Parameters
    ----------
    model : ElasticModel
    """

    def __init__(self, model):
        z_g = model.tables.z_g
        n = len(model.zs) * z_g * 2
        self.model = model
        self.have = np.zeros(n, dtype=bool)
        self.q_geo = np.zeros(n)  # gap + f b.U + A.rigid at the measurement: the constant part of the linear gap
        self.gap = np.zeros(n)
        self.b = np.zeros((n, 3))
        self.A = np.zeros((n, 3))
        self.point = np.zeros((n, 2))
        self.normal = np.zeros((n, 2))
        self.rigid_tooth = np.zeros(n, dtype=int)
        self.at_origin = np.zeros((n, 2))
        self.at_rot = np.zeros(n)
        loc = model.scene.flex_local - np.array([model.drive.r_m, 0.0])
        self.lever = float(np.hypot(loc[:, 0], loc[:, 1]).max())
        self.measured = 0

    def copy(self) -> MeasuredPairs:
        new = object.__new__(MeasuredPairs)
        new.__dict__.update({k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()})
        return new

    def _sec_motion(self, keys, motion):
        """Each pair's section motion ``(k, 3)`` from the rim's motion per section ``motion`` ``(S, 3)``."""
        return np.asarray(motion, dtype=float).reshape(-1, 3)[(keys // 2) // self.model.tables.z_g]

    def linear_gap(self, keys, fU, motion):
        """Linearised gap of pairs ``keys`` at the current state (``fU``: scaled elastic ``w, v, theta`` at each pair's
        tooth; ``motion``: the rim's motion against the rigid gear per section, ``(S, 3)``)."""
        sec = self._sec_motion(keys, motion)
        return self.q_geo[keys] - (self.b[keys] * fU).sum(axis=1) - (self.A[keys] * sec).sum(axis=1)

    def _move(self, keys, rot, origin):
        """Largest motion of any point of each pair's tooth since the pair was measured, mm."""
        t = keys // 2
        return np.hypot(*(origin[t] - self.at_origin[keys]).T) + np.abs(rot[t] - self.at_rot[keys]) * self.lever

    def update(self, rot, shift, origin, el, cand, motion, full: bool = False):
        """Measure again the pairs of teeth ``cand`` (flat tooth indices) that need it; return the keys within GAP_MARGIN."""
        m = self.model
        sec, tooth = np.divmod(cand, m.tables.z_g)
        keys = np.stack([2 * cand, 2 * cand + 1], axis=1).ravel()  # lower, upper of each tooth
        fU = np.repeat(m.scales[sec][:, None] * el[:, tooth].T, 2, axis=0)  # (2k, 3)
        if full:
            need = np.ones(len(keys), dtype=bool)
        else:
            seen = self.have[keys]
            need = ~seen
            k0 = keys[seen]
            move = self._move(k0, rot, origin)
            lin = self.linear_gap(k0, fU[seen], motion)
            # a tooth that has not moved (a warm start's first pass) keeps its exact measurement
            need[seen] = (lin < 2.0 * move + REFRESH_MARGIN) & (move > 1e-9)
        self._measure(np.nonzero(need)[0], keys, fU, rot, shift, origin, motion)
        lin = self.linear_gap(keys, fU, motion)
        return keys[lin < GAP_MARGIN]

    def _measure(self, idx, keys, fU, rot, shift, origin, motion):
        """Measure pairs ``keys[idx]`` on the exact geometry at the current poses."""
        if idx.size == 0:
            return
        m = self.model
        self.measured += idx.size
        k = keys[idx]
        t = k // 2
        lo, up, _ = m.scene.neighbours(shift[t], rot[t])
        g = pair_contacts(m.scene, rot[t], shift[t], np.where(k % 2 == 0, lo, up))
        ph = m.tables.angles[t % m.tables.z_g]
        c, sn = np.cos(ph), np.sin(ph)
        n, p = g.normal, g.point
        rel = p - origin[t]
        b = np.stack(
            [n[:, 0] * c + n[:, 1] * sn, -n[:, 0] * sn + n[:, 1] * c, rel[:, 0] * n[:, 1] - rel[:, 1] * n[:, 0]],
            axis=-1,
        )
        A = np.stack([n[:, 0], n[:, 1], p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]], axis=-1)
        self.have[k] = True
        self.gap[k] = g.gap
        self.b[k], self.A[k], self.point[k], self.normal[k] = b, A, p, n
        self.rigid_tooth[k] = g.rigid
        self.q_geo[k] = g.gap + (b * fU[idx]).sum(axis=1) + (A * self._sec_motion(k, motion)).sum(axis=1)
        self.at_origin[k] = origin[t]
        self.at_rot[k] = rot[t]

    def report(self, rot, shift, origin, el, cand, motion):
        """The pairs within GAP_MARGIN at a solved state and their gaps, exact wherever it can matter.

        Measured on the exact geometry: every pair that could be closing (as
        in :meth:`update`) and then every pair whose linearised gap, less
        twice its tooth's motion since measured, is below the smallest exact
        open gap (it could be the smallest clearance). The others are open by
        more than that and report the linearised gap (``exact`` False).

        Returns
        -------
        keys : (k,) int
        gap : (k,) float, mm
        exact : (k,) bool
        """
        self.update(rot, shift, origin, el, cand, motion)
        m = self.model
        sec, tooth = np.divmod(cand, m.tables.z_g)
        flat = np.stack([2 * cand, 2 * cand + 1], axis=1).ravel()
        fU = np.repeat(m.scales[sec][:, None] * el[:, tooth].T, 2, axis=0)
        while True:
            lin = self.linear_gap(flat, fU, motion)
            move = self._move(flat, rot, origin)
            exact = move <= 1e-9
            op = exact & (lin > 0.0)
            if op.any():
                m0 = float(lin[op].min())
                need = (~exact) & (lin - 2.0 * move < max(m0, REFRESH_MARGIN) + REFRESH_MARGIN)
            else:
                # no open pair measured at these poses yet: measure first the few whose lower bound on the
                # exact gap is smallest (one of them is likely the nearest), not every pair
                lb = np.where(exact, np.inf, lin - 2.0 * move)
                first = np.argsort(lb)[:_FIRST_OPEN]
                need = np.zeros(len(flat), dtype=bool)
                need[first[np.isfinite(lb[first])]] = True
            if not need.any():
                break
            self._measure(np.nonzero(need)[0], flat, fU, rot, shift, origin, motion)
        band = lin < GAP_MARGIN
        return flat[band], np.where(exact, self.gap[flat], lin)[band], exact[band]
