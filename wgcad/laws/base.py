"""The rim state and the base classes of the deformation laws: validation, folding into a quarter wave (docs/models.md 3.1, 3.6)."""

from __future__ import annotations

import abc
import math
import numbers
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from wgcad.errors import DesignError

__all__ = ["RimState", "Law"]

HALF_PI = 0.5 * math.pi

#: W0 must stay below r_m / W0_MAX_DIVISOR. The ring model of docs/models.md 3.1 is
#: linear in W0/r_m (its first-order kinematics err by O(W0/r_m)); a rim bent
#: by a quarter of its radius would be far past yield. Real drives use W0 of
#: about one module, i.e. ~1 % of r_m.
_W0_MAX_DIVISOR = 4.0

#: Largest wrap half-angle of the disc law (and of the external ring). A - B of
#: docs/models.md 3.3 vanishes like 0.24 (pi/2 - beta)^3 as beta -> 90 deg, and the
#: closed form subtracts O(1) terms to get it: at 85 deg A - B = 1.6e-4, so K
#: and w keep ~12 significant digits; beyond, the law degrades quickly
#: (89 deg: ~10 digits) while no real disc generator wraps that far.

# --------------------------------------------------------------------------
# state container


@dataclass(frozen=True, slots=True)
class RimState:
    """Neutral-line state at angles phi; every field an array with phi's shape (read-only).

    Attributes
    ----------
    phi : (...) float
        Angle of the material point from the generator major axis, rad
        (undeformed position).
    w : (...) float
        Radial displacement, mm (positive outward).
    dw, d2w : (...) float
        dw/dphi and d2w/dphi2, mm/rad and mm/rad^2.
    v : (...) float
        Tangential displacement, mm (positive counter-clockwise, v(0) = 0).
    dv : (...) float
        dv/dphi, mm/rad.
    theta : (...) float
        Counter-clockwise rotation of the rim cross-section (and of the
        neutral-line tangent) relative to the undeformed radius, rad.
    dtheta : (...) float
        dtheta/dphi.
    """

    phi: np.ndarray
    w: np.ndarray
    dw: np.ndarray
    d2w: np.ndarray
    v: np.ndarray
    dv: np.ndarray
    theta: np.ndarray
    dtheta: np.ndarray

    def __post_init__(self):
        shape = np.shape(self.phi)
        for name in self.__dataclass_fields__:
            arr = np.array(getattr(self, name), dtype=np.float64)  # own copy
            if arr.shape != shape:
                raise ValueError(f"RimState.{name} has shape {arr.shape}, phi has {shape}")
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)


# --------------------------------------------------------------------------
# validation helpers


def real_number(value, field_name: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DesignError(field_name, f"{what} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise DesignError(field_name, f"{what} must be finite, got {value!r}")
    return value


def check_w0_rm(w0, r_m) -> tuple[float, float]:
    r_m = real_number(r_m, "flexspline.rim_thickness", "neutral-line radius r_m")
    if r_m <= 0.0:
        raise DesignError("flexspline.rim_thickness", f"neutral-line radius r_m must be > 0 mm, got {r_m:g}")
    w0 = real_number(w0, "generator.w0_coef", "W0 = w0_coef * module")
    if w0 <= 0.0:
        raise DesignError("generator.w0_coef", f"W0 = w0_coef * module must be > 0 mm, got {w0:g} mm")
    if w0 >= r_m / _W0_MAX_DIVISOR:
        raise DesignError(
            "generator.w0_coef",
            f"W0 = {w0:g} mm must be < r_m/4 = {r_m / _W0_MAX_DIVISOR:g} mm: the ring model "
            "(docs/models.md 3.1) is linear in W0/r_m and a rim bent that far would yield "
            "(W0 is usually about one module)",
        )
    return w0, r_m


def check_beta(beta, law: str) -> float:
    if beta is None:
        raise DesignError("generator.beta_deg", f"is required by law '{law}'")
    beta = real_number(beta, "generator.beta_deg", "beta")
    if not 0.0 < beta < HALF_PI:
        raise DesignError("generator.beta_deg", f"must be in (0, 90) degrees, got {math.degrees(beta):.10g}")
    return beta


def check_two_waves(n_waves, law: str) -> None:
    if isinstance(n_waves, bool) or not isinstance(n_waves, numbers.Integral) or n_waves != 2:
        raise DesignError(
            "drive.waves",
            f"law '{law}' has two waves, got {n_waves!r} (only 'harmonic' takes other wave counts)",
        )


# --------------------------------------------------------------------------
# base classes


class Law(abc.ABC):
    """Abstract deformation law of the neutral line (docs/models.md 3.1, 3.6).

    Subclasses are frozen dataclasses with at least the attributes below.

    Attributes
    ----------
    name : str
        Registry key in :data:`LAWS` (value of ``generator.law``).
    w0 : float
        W0, mm: radial displacement on the major axis (> 0). For
        ``external_ring`` the neutral line moves *inward* there by W0.
    r_m : float
        Neutral-line radius, mm.
    n_waves : int
        Number of deformation waves.
    tooth_offset : float
        mm: the teeth of this cross-section stand this far out along their
        centre lines from the undeformed tooth form (a flexspline modified
        along the face, docs/models.md 13.4); 0 unless the design modifies
        it. It moves the teeth, not the neutral line: :meth:`state` ignores it.
    """

    name: ClassVar[str]
    w0: float
    r_m: float
    n_waves: int
    tooth_offset: float

    def state(self, phi) -> RimState:
        """Neutral-line state at the angles `phi`.

        Parameters
        ----------
        phi : (...) float or array_like
            Angle from the generator major axis, rad; any real value (the law
            is extended periodically and by symmetry).

        Returns
        -------
        RimState
            Every field an array of `phi`'s shape.
        """
        return self._state(np.array(phi, dtype=np.float64))

    #: whether every field scales with W0 (closed-form ring laws); the exact
    #: ellipse does not, its shape changes with the amplitude
    linear_in_w0: ClassVar[bool] = True

    def with_w0(self, w0: float) -> Law:
        """The same law with another amplitude W0 (mm), e.g. for coning."""
        return replace(self, w0=w0)

    @abc.abstractmethod
    def _state(self, phi: np.ndarray) -> RimState:
        """State for a float64 array `phi` (any shape)."""


class TwoWaveLaw(Law):
    """A two-wave law computed on [0, pi/2] and extended by symmetry.

    w is even about phi = 0 and about pi/2 (docs/models.md 3.3: "extend by
    symmetry"), hence pi-periodic; v, w', theta are odd about both. Folding
    into the quarter first makes these symmetries exact in floating point.
    """

    @abc.abstractmethod
    def _quarter(self, psi: np.ndarray) -> tuple[np.ndarray, ...]:
        """(w, dw, d2w, v, dv, theta, dtheta) for psi in [0, pi/2]."""

    def _state(self, phi: np.ndarray) -> RimState:
        red = phi - math.pi * np.round(phi / math.pi)  # in [-pi/2, pi/2]
        psi = np.abs(red)
        sgn = np.where(red < 0.0, -1.0, 1.0)
        w, dw, d2w, v, dv, th, dth = self._quarter(psi)
        return RimState(phi, w, sgn * dw, d2w, sgn * v, dv, sgn * th, dth)
