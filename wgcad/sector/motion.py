"""Motion law of a discrete-motion drive: flexspline rotation against generator angle, its dwell and move phases (docs/models.md 2.3)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from ..profiles.sector import SectorLayout

__all__ = ["MotionLaw", "Phase", "motion_law"]

#: two pieces whose speed ratios differ by less than this (relative) are one phase
_RATIO_TOL = 1e-9


@dataclass(frozen=True, slots=True)
class Phase:
    """One linear piece (or run of equal pieces) of the motion law. Angles rad.

    ``kind`` is ``"dwell"`` (output still) or ``"move"``; ``ratio`` is
    ``d phi_h / d phi_g`` (inf in a dwell).
    """

    kind: str
    start: float
    end: float
    output_step: float
    ratio: float

    @property
    def length(self) -> float:
        return self.end - self.start


@dataclass(frozen=True, slots=True)
class MotionLaw:
    """Flexspline rotation ``phi_g`` (rigid gear fixed) against generator angle ``phi_h``.

    Kinematic model: when the generator's major axis points at the centre of
    a rigid space, a flexspline tooth is centred in it (docs/models.md 1
    reference position, applied to every space), and successive spaces
    receive successive flexspline teeth; in between, ``phi_g`` is linear in
    ``phi_h``. For a plain rigid gear this is exactly ``phi_h / u_hg``; in a
    coupling sector (space pitch = flexspline pitch) ``phi_g`` stands still.

    Attributes
    ----------
    knots : (N + 1,) float
        Generator angles at the space centres over one turn (rad), the first
        repeated a turn later.
    values : (N + 1,) float
        ``phi_g`` there (rad).
    advance : float
        ``phi_g`` gained per generator turn, rad (``(z_g - N) 2 pi / z_g``).
    """

    knots: np.ndarray
    values: np.ndarray
    advance: float
    z_flex: int

    def __call__(self, phi_h) -> np.ndarray:
        """``phi_g`` at generator angles ``phi_h`` (rad, any shape, any number of turns)."""
        phi_h = np.asarray(phi_h, dtype=float)
        k0 = self.knots[0]
        turns = np.floor((phi_h - k0) / (2.0 * pi))
        local = phi_h - turns * 2.0 * pi
        return np.interp(local, self.knots, self.values) + turns * self.advance

    def phases(self) -> list[Phase]:
        """Dwell and move phases over one turn from the first knot, equal-ratio pieces merged."""
        out: list[Phase] = []
        for a, b, ga, gb in zip(self.knots[:-1], self.knots[1:], self.values[:-1], self.values[1:]):
            step = gb - ga
            # a dwell piece: the spaces are one flexspline pitch apart, to rounding
            dwell = abs(step) <= 1e-12 * (b - a) + 1e-15
            ratio = float("inf") if dwell else (b - a) / step
            kind = "dwell" if dwell else "move"
            if out and out[-1].kind == kind and (dwell or abs(out[-1].ratio - ratio) <= _RATIO_TOL * abs(ratio)):
                p = out[-1]
                out[-1] = Phase(kind, p.start, float(b), p.output_step + (0.0 if dwell else step), p.ratio)
            else:
                out.append(Phase(kind, float(a), float(b), 0.0 if dwell else float(step), ratio))
        return out

    def runs(self) -> list[Phase]:
        """Whole dwells and whole moves (the move's ramps and main piece together), ratio = length / output step."""
        out: list[Phase] = []
        for p in self.phases():
            if out and out[-1].kind == p.kind:
                q = out[-1]
                step = q.output_step + p.output_step
                out[-1] = Phase(
                    p.kind, q.start, p.end, step, float("inf") if p.kind == "dwell" else (p.end - q.start) / step
                )
            else:
                out.append(p)
        return out


def motion_law(layout: SectorLayout, z_flex: int) -> MotionLaw:
    """The :class:`MotionLaw` of a sectored (or any) rigid gear given by its tooth layout.

    The flexspline tooth that sits in space ``j`` is ``j + j0``; ``j0`` makes
    ``phi_g`` lie within half a flexspline pitch of 0 at the first space of
    the first coupling sector (or at the first space).
    """
    s = np.asarray(layout.spaces, dtype=float)
    n = len(s)
    p_g = 2.0 * pi / z_flex
    first = 0
    if layout.coupling.any():
        # first space whose both teeth are coupling teeth of the first coupling sector
        both = layout.coupling & np.roll(layout.coupling, -1) & (layout.sector == np.roll(layout.sector, -1))
        first = int(np.nonzero(both)[0][0])
    j0 = int(np.round(s[first] / p_g)) - first
    values = s - (np.arange(n) + j0) * p_g
    advance = (z_flex - n) * p_g
    knots = np.append(s, s[0] + 2.0 * pi)
    values = np.append(values, values[0] + advance)
    knots.setflags(write=False)
    values.setflags(write=False)
    return MotionLaw(knots, values, float(advance), z_flex)
