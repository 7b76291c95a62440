"""The harmonic law w = W0 cos(n_w phi) (docs/models.md 3.2)."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from wgcad.errors import DesignError

from .base import Law, RimState, check_w0_rm

__all__ = ["Harmonic"]

# --------------------------------------------------------------------------
# harmonic law


@dataclass(frozen=True, slots=True)
class Harmonic(Law):
    """Harmonic law w = W0 cos(n_w phi), any number of waves (docs/models.md 3.2).

    Parameters
    ----------
    w0 : float
        W0, mm.
    r_m : float
        Neutral-line radius, mm.
    n_waves : int, default 2
        Number of waves n_w >= 1.

    Examples
    --------
    >>> law = Harmonic(w0=0.88, r_m=80.0)
    >>> s = law.state([0.0, np.pi / 4])
    >>> np.round(s.w, 12).tolist()
    [0.88, 0.0]
    """

    name: ClassVar[str] = "harmonic"
    w0: float
    r_m: float
    n_waves: int = 2
    tooth_offset: float = 0.0

    def __post_init__(self):
        w0, r_m = check_w0_rm(self.w0, self.r_m)
        n = self.n_waves
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise DesignError("drive.waves", f"must be an integer >= 1, got {n!r}")
        object.__setattr__(self, "w0", w0)
        object.__setattr__(self, "r_m", r_m)
        object.__setattr__(self, "n_waves", int(n))

    def _state(self, phi: np.ndarray) -> RimState:
        # docs/models.md 3.2; theta = (v - w')/r_m, docs/models.md 3.1
        n, w0, r = self.n_waves, self.w0, self.r_m
        c, s = np.cos(n * phi), np.sin(n * phi)
        w = w0 * c
        return RimState(
            phi,
            w=w,
            dw=-n * w0 * s,
            d2w=-n * n * w0 * c,
            v=-(w0 / n) * s,
            dv=-w,
            theta=(w0 / r) * (n - 1.0 / n) * s,
            dtheta=(w0 / r) * (n * n - 1.0) * c,
        )
