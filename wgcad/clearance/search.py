"""Branch and bound over sampled tooth angles: which samples the polygons must evaluate (docs/models.md 7)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from .. import constants
from .scene import Scene, tooth_clearance_sections

__all__ = ["AuditSettings", "SectionSearch", "evaluate", "sample_phi", "fold"]


@dataclass(frozen=True, slots=True)
class AuditSettings:
    """What an audit computes.

    Attributes
    ----------
    angles : (A,) float
        Generator angles relative to the rigid gear, rad.
    sections : (S,) float
        Axial positions of the cross-sections, mm from the open end.
    use_period, use_waves, use_mirror, cull, bound : bool
        The work-skipping shortcuts (module docstring); all on by default.
    interference_tol : float
        Penetration (mm) reported as contact rather than interference.
    refine : bool
        Refine the figures on the exact tooth curves (:mod:`wgcad.clearance.refine`);
        off: the polygons' figures (within about twice the chord tolerance).
    """

    angles: np.ndarray
    sections: np.ndarray
    use_period: bool = True
    use_waves: bool = True
    use_mirror: bool = True
    cull: bool = True
    bound: bool = True
    interference_tol: float = constants.INTERFERENCE_TOL
    refine: bool = True


def sample_phi(scene: Scene, angles: np.ndarray) -> np.ndarray:
    """Tooth angles from the major axis for every (generator angle, tooth): ``(A, z_g)``, rad."""
    k = np.arange(scene.z_g)
    mat = 2 * pi * k[None, :] / scene.z_g + angles[:, None] / scene.ratios["u_hg"]
    return mat - angles[:, None]


def fold(phi: np.ndarray, period: float) -> np.ndarray:
    return (phi + 0.5 * period) % period - 0.5 * period


class SectionSearch:
    """Branch and bound for the smallest sampled clearance of one section (module docstring)."""

    def __init__(self, scene: Scene, phi_u: np.ndarray, z, settings: AuditSettings):
        self.scene, self.phi, self.z, self.settings = scene, phi_u, z, settings
        n = len(phi_u)
        self.value = np.full(n, np.nan)
        self.pairs = np.full((n, 3), np.nan)  # each evaluated sample's lower, upper and third pair
        self.evaluated = np.zeros(n, dtype=bool)
        self.radial = scene.radial_bound(scene.place(phi_u, z, local=scene.flex_tip_local))
        self.lower = self.radial.copy()
        zone = self.radial <= 0.0 if settings.cull else np.ones(n, dtype=bool)
        self.zone_mask = zone
        self.zone = np.nonzero(zone)[0]
        self.culled = 0
        self.V = 0.0
        # a sample whose polygon figure is within twice the polygon-curve difference of the
        # best may still be the exact minimum: nothing within that margin is skipped
        self.margin = 2.0 * scene.chord_gap if settings.refine else 0.0

    def prepare_bound(self) -> None:
        """Speed bound for branch and bound (only worth it with many samples)."""
        if self.settings.bound and self.zone.size >= 64:
            self.V = self.scene.speed_bound(self.phi[self.zone], self.z)

    def best(self) -> float:
        return float(np.nanmin(self.value)) if self.evaluated.any() else np.inf

    def coarse(self) -> np.ndarray:
        """Indices of the coarse pass: every sample without bounding, else every ``stride``-th in the zone."""
        self.stride = max(1, min(256, self.zone.size // 16))
        if not self.settings.bound or self.V == 0.0:
            return self.zone
        return self.zone[:: self.stride]

    def candidates(self, stride: int, best: float) -> np.ndarray:
        """Samples on this stride whose lower bound is below ``best`` (indices into :attr:`phi`)."""
        if self.V == 0.0 or stride >= self.stride:
            return np.zeros(0, dtype=int)
        zi, pz = self.zone, self.phi[self.zone]
        cand = np.arange(0, zi.size, stride)
        cand = cand[~self.evaluated[zi[cand]]]
        if cand.size == 0:
            return np.zeros(0, dtype=int)
        # bound from the nearest evaluated samples on both sides
        ev = np.nonzero(self.evaluated[zi])[0]
        pos = np.searchsorted(ev, cand)
        left = ev[np.clip(pos - 1, 0, len(ev) - 1)]
        right = ev[np.clip(pos, 0, len(ev) - 1)]
        vl = self.value[zi[left]] - self.V * np.abs(pz[cand] - pz[left])
        vr = self.value[zi[right]] - self.V * np.abs(pz[right] - pz[cand])
        lb = np.maximum(np.maximum(vl, vr), self.lower[zi[cand]])
        self.lower[zi[cand]] = lb
        return zi[cand[lb < best + self.margin]]

    def culled_needed(self, best: float) -> np.ndarray:
        """Culled samples whose radial bound does not clear ``best``: they must be evaluated."""
        out = np.nonzero(~self.zone_mask)[0]
        need = out[self.radial[out] < best + self.margin]
        self.culled = int(out.size - need.size)
        return need


#: samples evaluated per batch: large enough to amortise the per-call cost, small enough for
#: the progress bar to move every few tens of milliseconds
_CHUNK = 4096


def evaluate(scene: Scene, searches: list, picks: list, zs: list, done=None) -> float:
    """Evaluate the picked samples of every section in batches; return the best value so far."""
    phis = np.concatenate([r.phi[ix] for r, ix in zip(searches, picks)])
    if phis.size:
        zi = np.concatenate([np.full(len(ix), i) for i, ix in enumerate(picks)])
        vals = np.empty(len(phis))
        pairs = np.empty((len(phis), 3))
        for a in range(0, len(phis), _CHUNK):
            b = min(a + _CHUNK, len(phis))
            vals[a:b], pairs[a:b] = tooth_clearance_sections(scene, phis[a:b], zi[a:b], zs, pairs=True)
            if done is not None:
                done(b / len(phis))
        at = 0
        for r, ix in zip(searches, picks):
            n = len(ix)
            r.value[ix] = vals[at : at + n]
            r.pairs[ix] = pairs[at : at + n]
            r.lower[ix] = vals[at : at + n]
            r.evaluated[ix] = True
            at += n
    return min(r.best() for r in searches)
