"""Efficiency, no-load running, starting and backdriving torque from the loaded states' friction (docs/models.md 10.8).

Energy balance over a generator turn, first order in the friction: the input does the output's work plus every
loss, the losses taken at the frictionless model's forces. Per generator radian (N mm)

    T_in = T_out / |u_hg| + mu sum F |v_s| + (M_bearing + M_seals) |1 - 1/u_hg|,      eta = (T_out / |u_hg|) / T_in

(``v_s`` mm per generator radian, the bearing's rings turning ``|1 - 1/u_hg|`` against each other per generator
radian; ``M_seals`` the seals' given drag). Starting torque: the same at creep speed (Coulomb in the teeth, Palmgren's load term and his viscous
term's low-speed limit). Backdriving torque: the output torque whose work per generator radian pays the starting
losses, driving from the output with the input free (the drive self-locks when no torque does).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .bearing import PALMGREN_Z, STRIBECK_SUM, BearingFriction, palmgren_torque, static_rating
from .teeth import ToothFriction, tooth_friction

#: the input speed a start is taken at, rpm: far below Palmgren's nu n = 2000 for any viscosity the keys allow
CREEP_RPM = 1e-6

__all__ = [
    "CREEP_RPM",
    "FrictionSetup",
    "FrictionPoint",
    "Efficiency",
    "friction_point",
    "efficiency_table",
    "backdriving_torque",
]


@dataclass(frozen=True, slots=True)
class FrictionSetup:
    """What every state's friction needs: the coefficients, the bearing's pitch diameter and static rating, the
    ratio and the rings' relative turn per generator turn."""

    mu: float
    dm_mm: float
    c0_n: float
    nu_cst: float
    f0: float
    ratio: float
    ring_rate: float
    speed_rpm: float
    #: Palmgren's load factor z (0 with ``f0`` 0 and ``mu`` 0: no friction at all)
    z: float = PALMGREN_Z
    #: the seals' drag between the bearing's rings, N mm (``[bearing] seal_torque_nmm``)
    seal_nmm: float = 0.0

    @classmethod
    def of(cls, model, dm_mm: float, speed_rpm: float, mu: float | None = None) -> FrictionSetup:
        d = model.drive.design
        u = float(model.scene.ratios["u_hg"])
        br = model.bearing
        return cls(
            mu=d.load.tooth_friction if mu is None else float(mu),
            dm_mm=float(dm_mm),
            c0_n=static_rating(len(br.psi), br.q),
            nu_cst=d.bearing.lubricant_viscosity_cst,
            f0=d.bearing.viscous_friction_factor,
            ratio=abs(u),
            ring_rate=abs(1.0 - 1.0 / u),
            speed_rpm=float(speed_rpm),
            seal_nmm=d.bearing.seal_torque_nmm,
        )

    def bearing(self, p1_n: float, speed_rpm: float) -> BearingFriction:
        """Palmgren's torque at equivalent load ``p1_n`` and input speed ``speed_rpm`` (0: at rest)."""
        return palmgren_torque(p1_n, self.c0_n, self.dm_mm, self.nu_cst, speed_rpm * self.ring_rate, self.f0, self.z)


@dataclass(frozen=True, slots=True)
class FrictionPoint:
    """The friction of one loaded state (N mm per generator radian inside; the properties in N m at the input)."""

    torque_nm: float
    teeth: ToothFriction
    p1_n: float
    setup: FrictionSetup

    def bearing(self, speed_rpm: float | None = None) -> BearingFriction:
        return self.setup.bearing(self.p1_n, self.setup.speed_rpm if speed_rpm is None else speed_rpm)

    def loss(self, speed_rpm: float | None = None) -> float:
        """Every loss per generator radian, N mm."""
        return self.teeth.loss + (self.bearing(speed_rpm).total + self.setup.seal_nmm) * self.setup.ring_rate

    def input_torque_nm(self, speed_rpm: float | None = None) -> float:
        return (1e3 * self.torque_nm / self.setup.ratio + self.loss(speed_rpm)) * 1e-3

    def efficiency(self, speed_rpm: float | None = None) -> float:
        """Output power over input power (1 without friction; 0 at no load)."""
        out = 1e3 * self.torque_nm / self.setup.ratio
        tot = out + self.loss(speed_rpm)
        return out / tot if tot > 0 else 1.0

    @property
    def starting_loss(self) -> float:
        """The losses per generator radian as the drive starts, N mm: the teeth's Coulomb friction, Palmgren's load
        term and his viscous term at creep speed (its low-speed limit ``160e-7 f0 dm^3``)."""
        return self.teeth.loss + (self.bearing(CREEP_RPM).total + self.setup.seal_nmm) * self.setup.ring_rate


def friction_point(state, setup: FrictionSetup) -> FrictionPoint:
    """The friction of one loaded state: its tooth contacts and its balls (docs/models.md 10.8)."""
    c = state.contacts
    q = np.maximum(c["force"][c["kind"] == 0], 0.0)
    return FrictionPoint(float(state.torque_nm), tooth_friction(state, setup.mu), float(q.sum()) / STRIBECK_SUM, setup)


@dataclass(frozen=True, slots=True)
class Efficiency:
    """The catalogue's friction rows of one drive (N m at the input unless named otherwise)."""

    points: list
    no_load_nm: float
    starting_nm: float
    backdriving_nm: float | None
    self_locking: bool
    speeds_rpm: tuple
    #: efficiency ``(len(points), len(speeds_rpm))``
    table: np.ndarray


def backdriving_torque(points) -> tuple[float | None, bool]:
    """``(output torque N m, self-locking)``: the smallest output torque whose work per generator radian pays the
    starting losses, ``T / |u| = starting losses(T)`` (linear between the states); ``(None, True)`` when no state's
    torque does (the drive self-locks over the range solved)."""
    pts = sorted(points, key=lambda p: p.torque_nm)
    T = np.array([p.torque_nm for p in pts])
    g = np.array([1e3 * p.torque_nm / p.setup.ratio - p.starting_loss for p in pts])
    k = np.nonzero(g >= 0)[0]
    if k.size == 0:
        return None, True
    i = int(k[0])
    if i == 0:
        return float(T[0]), False
    return float(T[i - 1] + (T[i] - T[i - 1]) * (-g[i - 1]) / (g[i] - g[i - 1])), False


def efficiency_table(states, setup: FrictionSetup, speeds_rpm=(500.0, 1000.0, 2000.0, 3500.0)) -> Efficiency:
    """The friction rows from loaded states of one drive (one at zero torque among them), torques ascending."""
    pts = sorted((friction_point(s, setup) for s in states), key=lambda p: p.torque_nm)
    zero = pts[0]
    if zero.torque_nm != 0:
        raise ValueError("efficiency_table needs the unloaded state among the states")
    table = np.array([[p.efficiency(n) for n in speeds_rpm] for p in pts])
    tb, lock = backdriving_torque(pts)
    return Efficiency(
        points=pts,
        no_load_nm=zero.input_torque_nm(),
        starting_nm=1e-3 * zero.starting_loss,
        backdriving_nm=tb,
        self_locking=lock,
        speeds_rpm=tuple(float(n) for n in speeds_rpm),
        table=table,
    )
