"""A torque sweep of the loaded drive as records: each level's load state and entry, the stiffness between levels
(docs/models.md 4.1, 5). In mm, rad, N and N mm; :mod:`wgcad.report.load` rounds and words them."""

from __future__ import annotations

import time
from dataclasses import dataclass
from math import pi

import numpy as np

from wgcad.constants import INTERFERENCE_TOL

from .cam import MountedState, mounted
from .mesh import entry_gaps
from .model import ElasticModel
from .state import LoadState, solve_load

__all__ = ["LoadLevel", "LoadSweep", "law_departure", "torque_sweep", "wave_of"]


def wave_of(phi):
    """Index of the wave (major axis at 0 or pi) a tooth angle belongs to."""
    return (np.cos(phi) < 0.0).astype(int)


def _entry_laws(st: LoadState) -> list:
    """The laws whose entry gaps a level reports: each section, each wave."""
    return [law.shifted(phase) for phase in (0.0, pi) for law in st.laws]


@dataclass(slots=True)
class LoadLevel:
    """One torque level: its load state and the entry of its teeth (:class:`wgcad.clearance.entry.EntryPassage` of
    each wave, 0 then pi, and section, ``model.zs``)."""

    state: LoadState
    entry: list

    @property
    def torque_nm(self) -> float:
        return self.state.torque_nm

    @property
    def entry_gap(self) -> float:
        """The smallest entry gap Delta over waves and sections, mm (NaN where no tip crosses the rigid tip circle)."""
        gaps = [p.delta for p in self.entry if np.isfinite(p.delta)]
        return min(gaps) if gaps else float("nan")

    @property
    def tooth(self) -> np.ndarray:
        """Which contacts are teeth (the others are balls)."""
        return self.state.contacts["kind"] == 1

    @property
    def tooth_forces(self) -> np.ndarray:
        """Force on each flexspline tooth (all sections and flanks), N, ``(z_g,)``."""
        c, tooth = self.state.contacts, self.tooth
        per = np.zeros(self.state.model.drive.design.drive.z_flex)
        np.add.at(per, c["tooth"][tooth], c["force"][tooth])
        return per

    @property
    def teeth_in_contact(self) -> int:
        c = self.state.contacts
        return int(len(np.unique(c["tooth"][self.tooth & (c["force"] > 0)])))

    @property
    def min_clearance(self) -> float:
        """Smallest gap of the tooth pairs that carry no load, mm (NaN when every pair carries load)."""
        c = self.state.contacts
        free = self.tooth & (c["force"] <= 0)
        return float(c["gap"][free].min()) if free.any() else float("nan")

    @property
    def ball_loads(self) -> np.ndarray:
        c = self.state.contacts
        return c["force"][~self.tooth]


@dataclass(slots=True)
class LoadSweep:
    """Every torque level of a sweep (each warm-started from the previous), with the drive's model and the inputs."""

    model: ElasticModel
    levels: list
    cam_offset_um: float
    cam_offset_deg: float
    mounted: MountedState | None
    elapsed_s: float
    summary_s: float

    def secant_stiffness(self) -> list:
        """Torque over wind-up from the first level (zero load when the sweep starts there), N mm/rad per level
        (None where the wind-up has not grown)."""
        s0 = self.levels[0].state if self.levels else None
        out = []
        for lv in self.levels:
            dth = lv.state.wind_up - s0.wind_up
            out.append(1e3 * (lv.torque_nm - s0.torque_nm) / dth if dth > 0 else None)
        return out

    def tangent_stiffness(self) -> list:
        """The increment between neighbouring levels, N mm/rad (None where the wind-up has not grown)."""
        out = []
        for a, b in zip(self.levels[:-1], self.levels[1:]):
            dth = b.state.wind_up - a.state.wind_up
            out.append(1e3 * (b.torque_nm - a.torque_nm) / dth if dth > 0 else None)
        return out

    @property
    def entry_gap_closes(self) -> bool:
        """The entry gap closes (beyond the interference tolerance) at some level: tip interference."""
        return any(lv.entry_gap < -INTERFERENCE_TOL for lv in self.levels if np.isfinite(lv.entry_gap))


def torque_sweep(
    model: ElasticModel,
    torques_nm,
    cam_offset_um: float = 0.0,
    cam_offset_deg: float = 0.0,
    tol: float | None = None,
    progress=None,
) -> LoadSweep:
    """Solve every torque level (each warm-started from the previous) and measure each level's entry."""
    kw = {} if tol is None else {"tol": tol}
    states = []
    prev = None
    t0 = time.perf_counter()
    for k, T in enumerate(torques_nm):
        st = solve_load(model, float(T), cam_offset_um, cam_offset_deg, warm=prev, **kw)
        prev = st
        states.append(st)
        if progress:
            progress(k + 1, len(torques_nm), "load levels")
    # the entry gaps of every level refined on the exact curves in one engine call (its cost is per call)
    t1 = time.perf_counter()
    n_e = 2 * len(model.zs)
    gaps = entry_gaps(model.scene, [law for st in states for law in _entry_laws(st)])
    levels = [LoadLevel(st, gaps[k * n_e : (k + 1) * n_e]) for k, st in enumerate(states)]
    mnt = mounted(model, states[0].cam_offset if states else np.zeros(2))
    t_summary = time.perf_counter() - t1
    return LoadSweep(model, levels, cam_offset_um, cam_offset_deg, mnt, time.perf_counter() - t0, t_summary)


def law_departure(model: ElasticModel, mt: MountedState) -> tuple[float, float]:
    """How far the rim on the cam at no load departs from the design's law at the teeth: the largest difference of
    radial displacement (mm, signed) and the tooth angle where it lies (rad)."""
    tab = model.tables
    phi = tab.angles[: tab.z_g]
    el = tab.tooth_field(mt.loads)
    w = el[0] + mt.rigid[0] * np.cos(phi) + mt.rigid[1] * np.sin(phi)
    dev = w - model.drive.law.state(phi).w
    i = int(np.argmax(np.abs(dev)))
    return float(dev[i]), float(phi[i])
