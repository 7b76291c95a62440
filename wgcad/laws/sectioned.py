"""Laws given by two closed-form sections meeting at beta: the disc generator, its mirror the external ring, and the four-force cam (docs/models.md 3.3, 3.4)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from wgcad.errors import DesignError

from .base import HALF_PI, RimState, TwoWaveLaw, check_beta, check_w0_rm

__all__ = ["Disc", "ExternalRing", "FourForce"]

_DISC_BETA_MAX = math.radians(85.0)


def _ff_band_edge() -> float:
    """Root of tan(b) = pi/2 - b by Newton from the right (convex, increasing: monotone)."""
    b = 0.8
    for _ in range(50):
        step = (math.tan(b) + b - HALF_PI) / (1.0 / math.cos(b) ** 2 + 1.0)
        b -= step
        if abs(step) <= 4e-16:
            break
    return b


#: Four-force law (docs/models.md 3.4): for beta in (BETA_LO, BETA_HI) the shape is
#: no two-wave oval. At BETA_LO (40.7065 deg), tan(beta) = pi/2 - beta and
#: w''(0) changes sign (w(0) stops being the largest radius); D vanishes at
#: 43.89 deg, where no finite force gives w(0) = W0; at BETA_HI = pi/2 - BETA_LO,
#: beta tan(beta) = 1 and w''(pi/2) changes sign (w(pi/2) stops being the
#: smallest). Outside the band w decreases monotonically from 0 to pi/2
#: (outward forces below BETA_LO, inward forces above BETA_HI; the two ranges
#: are mirror images by a quarter turn) and |D| >= 0.258.
FF_BETA_LO = _ff_band_edge()
FF_BETA_HI = HALF_PI - FF_BETA_LO


# --------------------------------------------------------------------------
# disc law and its mirror image, the external ring


@dataclass(frozen=True, slots=True)
class _SectionedLaw(TwoWaveLaw):
    """A two-wave law given by two closed-form sections meeting at ``beta`` (docs/models.md 3.3, 3.4).

    Subclasses provide ``_sections(phi) -> (section I fields, section II fields)``.
    """

    def closed_forms(self, phi) -> tuple[RimState, RimState]:
        """Both closed-form sections at raw `phi` (no folding).

        For checks of continuity at beta: section I is valid on
        0 <= phi <= beta, section II on beta <= phi <= pi/2.

        Parameters
        ----------
        phi : (...) float

        Returns
        -------
        (RimState, RimState)
            Section I and section II formulas evaluated at `phi`.
        """
        phi = np.array(phi, dtype=np.float64)
        s1, s2 = self._sections(phi)
        return RimState(phi, *s1), RimState(phi, *s2)

    def _quarter(self, psi):
        sec1, sec2 = self._sections(psi)
        on_section_one = psi <= self.beta
        return tuple(np.where(on_section_one, a, b) for a, b in zip(sec1, sec2))


@dataclass(frozen=True, slots=True)
class _DiscShape(_SectionedLaw):
    """Disc-generator shape of docs/models.md 3.3 times a sign (+1 disc, -1 external ring)."""

    _sign: ClassVar[float] = 1.0

    w0: float
    r_m: float
    beta: float
    tooth_offset: float = 0.0
    n_waves: int = field(default=2, init=False)
    _A: float = field(init=False, repr=False, compare=False)
    _B: float = field(init=False, repr=False, compare=False)
    _C: float = field(init=False, repr=False, compare=False)
    _K: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = check_w0_rm(self.w0, self.r_m)
        beta = check_beta(self.beta, self.name)
        if beta > _DISC_BETA_MAX:
            raise DesignError(
                "generator.beta_deg",
                f"must be <= 85 degrees for law '{self.name}', got {math.degrees(beta):.10g}: "
                "A - B of docs/models.md 3.3 vanishes as beta -> 90 deg and the closed form "
                "loses its precision to cancellation",
            )
        sb, cb = math.sin(beta), math.cos(beta)
        # docs/models.md 3.3
        A = HALF_PI - sb * cb - beta
        B = -2.0 * sb + (4.0 * beta / math.pi) * sb + (4.0 / math.pi) * cb
        C = (4.0 / math.pi) * (beta * sb + cb)  # = B + 2 sin(beta)
        for k, val in (("w0", w0), ("r_m", r_m), ("beta", beta), ("_A", A), ("_B", B), ("_C", C), ("_K", w0 / (A - B))):
            object.__setattr__(self, k, val)

    def _sections(self, phi):
        A, B, C, K, r = self._A, self._B, self._C, self._K * self._sign, self.r_m
        sb2 = math.sin(self.beta) ** 2
        c, s = np.cos(phi), np.sin(phi)
        # docs/models.md 3.3, section I (on the disc, constant curvature)
        w1 = K * (A * c - B)
        sec1 = (
            w1,
            -K * A * s,
            -K * A * c,
            -K * (A * s - B * phi),
            -w1,
            K * B * phi / r,
            np.full_like(phi, K * B / r),
        )
        # docs/models.md 3.3, section II (free span)
        q = HALF_PI - phi
        w2 = K * ((1.0 + sb2) * s + q * c - 2.0 * math.sin(self.beta) - B)
        sec2 = (
            w2,
            K * (sb2 * c - q * s),
            K * ((1.0 - sb2) * s - q * c),
            K * ((2.0 + sb2) * c - q * s - C * q),
            -w2,
            (K / r) * (2.0 * c - C * q),
            (K / r) * (C - 2.0 * s),
        )
        return sec1, sec2


@dataclass(frozen=True, slots=True)
class Disc(_DiscShape):
    """Disc generator with wrap half-angle beta (docs/models.md 3.3), two waves.

    Parameters
    ----------
    w0 : float
        W0, mm.
    r_m : float
        Neutral-line radius, mm.
    beta : float
        Wrap half-angle of each disc, rad, in (0, 85 deg].

    Examples
    --------
    >>> law = Disc(w0=0.72, r_m=60.0, beta=np.radians(30.0))
    >>> round(float(law.state(0.0).w), 12), round(float(law.state(np.pi / 2).v), 12)
    (0.72, 0.0)
    """

    name: ClassVar[str] = "disc"
    _sign: ClassVar[float] = 1.0


@dataclass(frozen=True, slots=True)
class ExternalRing(_DiscShape):
    """External-deformation ring generator (docs/models.md 3.5): the disc law with the opposite sign.

    Washers squeeze the flexspline from outside on the major axis, so the
    neutral line moves inward there: ``state(0).w == -w0``. Every field (w, v,
    theta and derivatives) is the negative of :class:`Disc`'s.

    Parameters
    ----------
    w0 : float
        W0 > 0, mm: inward displacement on the major axis.
    r_m : float
        Neutral-line radius, mm.
    beta : float
        Half-angle of constant curvature, rad, in (0, 85 deg].

    Examples
    --------
    >>> law = ExternalRing(w0=0.9, r_m=135.0, beta=np.radians(40.0))
    >>> round(float(law.state(0.0).w), 12)
    -0.9
    """

    name: ClassVar[str] = "external_ring"
    _sign: ClassVar[float] = -1.0


# --------------------------------------------------------------------------
# four-force law


@dataclass(frozen=True, slots=True)
class FourForce(_SectionedLaw):
    """Cam shaped as a ring deformed by four radial forces at +-beta, pi+-beta (docs/models.md 3.4).

    Parameters
    ----------
    w0 : float
        W0, mm.
    r_m : float
        Neutral-line radius, mm.
    beta : float
        Angle of the forces from the major axis, rad, in (0, 90 deg) outside
        (40.71, 49.29) deg, where the ring is no two-wave oval.

    Examples
    --------
    >>> law = FourForce(w0=0.88, r_m=80.0, beta=np.radians(35.0))
    >>> round(float(law.state(0.0).w), 12)
    0.88
    """

    name: ClassVar[str] = "four_force"

    w0: float
    r_m: float
    beta: float
    tooth_offset: float = 0.0
    n_waves: int = field(default=2, init=False)
    _D: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = check_w0_rm(self.w0, self.r_m)
        beta = check_beta(self.beta, self.name)
        if FF_BETA_LO < beta < FF_BETA_HI:
            raise DesignError(
                "generator.beta_deg",
                f"must not lie in ({math.degrees(FF_BETA_LO):.2f}, "
                f"{math.degrees(FF_BETA_HI):.2f}) "
                f"degrees for law 'four_force', got {math.degrees(beta):.10g}: there the ring's "
                "largest radius leaves the major axis or its smallest the minor axis, and "
                "D = 8/cos(beta) - pi(pi - 2 beta + 2 tan(beta)) vanishes at 43.89 deg "
                "(docs/models.md 3.4)",
            )
        D = 8.0 / math.cos(beta) - math.pi * (math.pi - 2.0 * beta + 2.0 * math.tan(beta))
        for k, val in (("w0", w0), ("r_m", r_m), ("beta", beta), ("_D", D)):
            object.__setattr__(self, k, val)

    def _sections(self, phi):
        beta, r = self.beta, self.r_m
        k = self.w0 / self._D
        tb = math.tan(beta)
        c0 = 8.0 / math.cos(beta)
        c, s = np.cos(phi), np.sin(phi)
        pi = math.pi

        # docs/models.md 3.4, section I; v = -int_0^phi w (v' = -w, v(0) = 0, docs/models.md 3.1)
        a1 = pi * (pi - 2.0 * beta + 2.0 * tb)
        g1 = 2.0 * pi * tb
        w1 = k * (c0 - a1 * c - g1 * phi * s)
        dw1 = k * (a1 * s - g1 * (s + phi * c))
        d2w1 = k * (a1 * c - g1 * (2.0 * c - phi * s))
        v1 = -k * (c0 * phi - a1 * s - g1 * (s - phi * c))

        # docs/models.md 3.4, section II; v = int_phi^(pi/2) w (v(pi/2) = 0)
        a2 = 2.0 * pi * (1.0 + beta * tb)
        q = pi - 2.0 * phi
        w2 = k * (c0 - a2 * s - pi * q * c)
        dw2 = k * (-2.0 * pi * beta * tb * c + pi * q * s)
        d2w2 = k * ((2.0 * pi * beta * tb - 2.0 * pi) * s + pi * q * c)
        v2 = k * (0.5 * c0 * q - a2 * c - pi * (2.0 * c - q * s))

        def full(w, dw, d2w, v):
            # theta = (v - w')/r_m, docs/models.md 3.1; dtheta = (v' - w'')/r_m with v' = -w
            return (w, dw, d2w, v, -w, (v - dw) / r, (-w - d2w) / r)

        return full(w1, dw1, d2w1, v1), full(w2, dw2, d2w2, v2)
