"""Bolt circles sized for the torque they carry: metric bolts in clearance holes, a friction-grip joint (numpy-free).

A bolt circle of ``n`` bolts at radius ``r`` clamping two faces carries a
torque by friction: ``T_cap = n mu F_V r`` with ``F_V`` each bolt's preload.
The rule wgcad applies, every factor stated so a designer can change it:

* property class 12.9 bolts (ISO 898-1; what strain-wave drive makers
  specify for their flanges), preload ``F_V = 0.7 R_p0.2 A_s`` with
  ``R_p0.2 = 1100 MPa`` and ``A_s`` the thread's stress area (ISO 898-1
  table of metric coarse threads);
* friction ``mu = 0.12`` between dry machined steel faces (a low value of
  the usual 0.1-0.2: the joint should not rely on more);
* a safety factor of 2 on slip: ``T_cap >= 2 T`` with ``T`` the design
  torque (``[load] rated_torque_nm``, the torque the parts are sized for;
  not the datasheet's rated torque, docs/glossary.md); the cup's bolts and the rigid
  gear's carry the whole output torque (the generator's input torque is
  the output over the ratio: within 1 % of it on these drives);
* clearance holes of ISO 273 "medium"; every ligament (hole to the inner
  and to the outer edge of its annulus) at least half the hole, and the
  holes at least a hole apart (centres two holes apart).

The bolt circle sits as far out as its outer ligament allows (the torque
it carries grows with its radius); the smallest bolt that carries the
torque in a count that fits is chosen; a bolt circle that cannot carry it
is refused, naming the key to change.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import DesignError

__all__ = ["METRIC", "BoltChoice", "carry", "choose_bolts", "RULE"]

#: (name, stress area A_s mm^2, ISO 273 medium clearance hole mm)
METRIC = (
    ("M2", 2.07, 2.4),
    ("M2.5", 3.39, 2.9),
    ("M3", 5.03, 3.4),
    ("M4", 8.78, 4.5),
    ("M5", 14.2, 5.5),
    ("M6", 20.1, 6.6),
    ("M8", 36.6, 9.0),
    ("M10", 58.0, 11.0),
    ("M12", 84.3, 13.5),
    ("M16", 157.0, 17.5),
    ("M20", 245.0, 22.0),
)
RP02_MPA = 1100.0  # class 12.9
PRELOAD_FRACTION = 0.7
MU = 0.12
SLIP_SAFETY = 2.0
COUNTS = (6, 8, 10, 12, 16, 20, 24, 32)
#: the rule in one line, for the summaries
RULE = (
    f"friction grip: class 12.9 bolts preloaded to {PRELOAD_FRACTION:g} R_p0.2, mu {MU:g}, slip safety {SLIP_SAFETY:g} "
    "on the design torque ([load] rated_torque_nm); ISO 273 medium holes, ligaments >= half a hole"
)


@dataclass(frozen=True, slots=True)
class BoltChoice:
    """A bolt circle: ``count`` bolts of ``size`` in ``hole_mm`` holes at ``radius_mm``, and the torque it carries."""

    size: str
    count: int
    hole_mm: float
    radius_mm: float
    capacity_nm: float

    def text(self, torque_nm: float) -> str:
        return (
            f"{self.count} x {self.size} (12.9) in {self.hole_mm:g} mm holes on {2 * self.radius_mm:.1f} mm: "
            f"slip at {self.capacity_nm:.0f} N m = {self.capacity_nm / torque_nm:.1f} x the design torque {torque_nm:g} N m"
        )


def carry(stress_area_mm2: float, count: int, radius_mm: float) -> float:
    """Torque (N m) a friction-grip bolt circle transmits before slip (module docstring; no safety factor)."""
    preload_n = PRELOAD_FRACTION * RP02_MPA * stress_area_mm2
    return count * MU * preload_n * radius_mm * 1e-3


def choose_bolts(torque_nm: float, r_lo: float, r_hi: float | None, key: str, place=None) -> BoltChoice:
    """The smallest metric bolts, in the fewest holes, that carry ``torque_nm`` with the slip safety.

    ``r_lo``/``r_hi``: the annulus the holes sit in (mm; ``r_hi`` None: the
    outer edge follows the hole, as a flange's does). ``place(hole)`` gives
    the bolt circle's radius for a hole size (default: as far out as the
    outer ligament of half a hole allows).
    ``key``: the ``[parts]`` prefix named when nothing fits.
    """
    # a workshop's preference: up to 16 bolts of the smallest size that carries the torque, more only if no size
    # does with 16
    for most in (16, max(COUNTS)):
        for size, area, hole in METRIC:
            r = place(hole) if place is not None else r_hi - hole
            if r - hole < r_lo - 1e-9 or (r_hi is not None and r + hole > r_hi + 1e-9):
                continue  # a ligament below half a hole on one side
            for n in (c for c in COUNTS if c <= most):
                if 2.0 * r * math.sin(math.pi / n) < 2.0 * hole:
                    break  # the holes closer than a hole apart: more of them fit even less
                cap = carry(area, n, r)
                if cap >= SLIP_SAFETY * torque_nm:
                    return BoltChoice(size, n, hole, r, cap)
    raise DesignError(
        f"parts.{key}_bolt_circle_diameter",
        f"no bolt circle of metric 12.9 bolts between radius {r_lo:.2f} and {'the edge' if r_hi is None else f'{r_hi:.2f}'} mm "
        f"carries {torque_nm:g} N m with a slip safety of {SLIP_SAFETY:g} ({RULE}); give the bolt circle, count and "
        "holes in [parts], or a larger part",
    )
