"""Deformation laws of the flexspline neutral line: w, v, theta and derivatives (docs/models.md 3)."""

from __future__ import annotations

import abc
import math
import numbers
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from wgcad.constants import NEWTON_TOL
from wgcad.errors import DesignError, GeometryError

__all__ = [
    "RimState",
    "Law",
    "Harmonic",
    "Disc",
    "FourForce",
    "Ellipse",
    "ExternalRing",
    "LAWS",
    "make_law",
]

_HALF_PI = 0.5 * math.pi

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
_DISC_BETA_MAX = math.radians(85.0)


def _ff_band_edge() -> float:
    """Root of tan(b) = pi/2 - b by Newton from the right (convex, increasing: monotone)."""
    b = 0.8
    for _ in range(50):
        step = (math.tan(b) + b - _HALF_PI) / (1.0 / math.cos(b) ** 2 + 1.0)
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
_FF_BETA_LO = _ff_band_edge()
_FF_BETA_HI = _HALF_PI - _FF_BETA_LO


# --------------------------------------------------------------------------
# state container


@dataclass(frozen=True)
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


def _real(value, field_name: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise DesignError(field_name, f"{what} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise DesignError(field_name, f"{what} must be finite, got {value!r}")
    return value


def _check_w0_rm(w0, r_m) -> tuple[float, float]:
    r_m = _real(r_m, "flexspline.rim_thickness", "neutral-line radius r_m")
    if r_m <= 0.0:
        raise DesignError("flexspline.rim_thickness", f"neutral-line radius r_m must be > 0 mm, got {r_m:g}")
    w0 = _real(w0, "generator.w0_coef", "W0 = w0_coef * module")
    if w0 <= 0.0:
        raise DesignError(
            "generator.w0_coef", f"W0 = w0_coef * module must be > 0 mm, got {w0:g} mm"
        )
    if w0 >= r_m / _W0_MAX_DIVISOR:
        raise DesignError(
            "generator.w0_coef",
            f"W0 = {w0:g} mm must be < r_m/4 = {r_m / _W0_MAX_DIVISOR:g} mm: the ring model "
            "(docs/models.md 3.1) is linear in W0/r_m and a rim bent that far would yield "
            "(W0 is usually about one module)",
        )
    return w0, r_m


def _check_beta(beta, law: str) -> float:
    if beta is None:
        raise DesignError("generator.beta_deg", f"is required by law '{law}'")
    beta = _real(beta, "generator.beta_deg", "beta")
    if not 0.0 < beta < _HALF_PI:
        raise DesignError(
            "generator.beta_deg", f"must be in (0, 90) degrees, got {math.degrees(beta):.10g}"
        )
    return beta


def _check_two_waves(n_waves, law: str) -> None:
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
    """

    name: ClassVar[str]
    w0: float
    r_m: float
    n_waves: int

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

    def with_w0(self, w0: float) -> "Law":
        """The same law with another amplitude W0 (mm), e.g. for coning."""
        return replace(self, w0=w0)

    @abc.abstractmethod
    def _state(self, phi: np.ndarray) -> RimState:
        """State for a float64 array `phi` (any shape)."""


class _TwoWaveLaw(Law):
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


# --------------------------------------------------------------------------
# harmonic law


@dataclass(frozen=True)
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

    def __post_init__(self):
        w0, r_m = _check_w0_rm(self.w0, self.r_m)
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


# --------------------------------------------------------------------------
# disc law and its mirror image, the external ring


@dataclass(frozen=True)
class _SectionedLaw(_TwoWaveLaw):
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


@dataclass(frozen=True)
class _DiscShape(_SectionedLaw):
    """Disc-generator shape of docs/models.md 3.3 times a sign (+1 disc, -1 external ring)."""

    _sign: ClassVar[float] = 1.0

    w0: float
    r_m: float
    beta: float
    n_waves: int = field(default=2, init=False)
    _A: float = field(init=False, repr=False, compare=False)
    _B: float = field(init=False, repr=False, compare=False)
    _C: float = field(init=False, repr=False, compare=False)
    _K: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = _check_w0_rm(self.w0, self.r_m)
        beta = _check_beta(self.beta, self.name)
        if beta > _DISC_BETA_MAX:
            raise DesignError(
                "generator.beta_deg",
                f"must be <= 85 degrees for law '{self.name}', got {math.degrees(beta):.10g}: "
                "A - B of docs/models.md 3.3 vanishes as beta -> 90 deg and the closed form "
                "loses its precision to cancellation",
            )
        sb, cb = math.sin(beta), math.cos(beta)
        # docs/models.md 3.3
        A = _HALF_PI - sb * cb - beta
        B = -2.0 * sb + (4.0 * beta / math.pi) * sb + (4.0 / math.pi) * cb
        C = (4.0 / math.pi) * (beta * sb + cb)  # = B + 2 sin(beta)
        for k, val in (("w0", w0), ("r_m", r_m), ("beta", beta), ("_A", A), ("_B", B),
                       ("_C", C), ("_K", w0 / (A - B))):
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
        q = _HALF_PI - phi
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



@dataclass(frozen=True)
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


@dataclass(frozen=True)
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


@dataclass(frozen=True)
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
    n_waves: int = field(default=2, init=False)
    _D: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = _check_w0_rm(self.w0, self.r_m)
        beta = _check_beta(self.beta, self.name)
        if _FF_BETA_LO < beta < _FF_BETA_HI:
            raise DesignError(
                "generator.beta_deg",
                f"must not lie in ({math.degrees(_FF_BETA_LO):.2f}, "
                f"{math.degrees(_FF_BETA_HI):.2f}) "
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


# --------------------------------------------------------------------------
# exact elliptical cam


def ellipe(m):
    """Complete elliptic integral of the second kind (scipy.special, imported on first use: ~0.35 s)."""
    from scipy.special import ellipe as _e

    return _e(m)


def ellipeinc(phi, m):
    """Incomplete elliptic integral of the second kind (scipy.special, imported on first use)."""
    from scipy.special import ellipeinc as _e

    return _e(phi, m)


def _solve_ellipe(target: float) -> float:
    """Parameter m in [0, 1) with E(m) = target, for target in (1, pi/2].

    Bisection down to adjacent floats (E is strictly decreasing): ~60-90
    scalar evaluations, robust where Newton's E'(m) = (E - K)/(2m) is 0/0.
    """
    lo, hi = 0.0, 1.0
    while True:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            return lo if abs(ellipe(lo) - target) <= abs(ellipe(hi) - target) else hi
        if ellipe(mid) > target:
            lo = mid
        else:
            hi = mid


@dataclass(frozen=True)
class Ellipse(_TwoWaveLaw):
    """Exact elliptical cam: the neutral line is an ellipse offset outward by `offset`.

    Not a ring-theory law: the geometry is exact. The base ellipse (semi-axes
    `a` > `b`, major axis on +x) is chosen so that the neutral line's largest
    radius is r_m + W0 (at phi = 0) and its perimeter is 2 pi r_m (the rim is
    inextensible, docs/models.md 3.1). The material point of undeformed angle phi
    sits at arc length r_m phi from the major-axis vertex. w, v are the
    components of P(phi) - r_m e_r(phi) on e_r(phi), e_t(phi); theta is the
    angle of the deformed tangent from e_t(phi). Exact relations used
    (|dP/dphi| = r_m, curvature kappa of the neutral line):
    w' = v - r_m sin(theta), v' = r_m (cos(theta) - 1) - w,
    theta' = r_m kappa - 1, w'' = v' - r_m cos(theta) theta'.

    Parameters
    ----------
    w0 : float
        W0, mm.
    r_m : float
        Neutral-line radius, mm.
    offset : float, default 0.0
        Outward offset of the neutral line from the ellipse, mm (>= 0), e.g.
        bearing and half the rim for an elliptical cam.

    Attributes
    ----------
    a, b : float
        Semi-axes of the base ellipse, mm.

    Examples
    --------
    >>> law = Ellipse(w0=0.88, r_m=80.0)
    >>> round(law.a, 12), bool(abs(law.state(np.pi / 2).v) < 1e-12)
    (80.88, True)
    """

    linear_in_w0: ClassVar[bool] = False
    name: ClassVar[str] = "ellipse"

    w0: float
    r_m: float
    offset: float = 0.0
    n_waves: int = field(default=2, init=False)
    a: float = field(init=False)
    b: float = field(init=False)
    _m: float = field(init=False, repr=False, compare=False)
    _E: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = _check_w0_rm(self.w0, self.r_m)
        d = _real(self.offset, "generator.offset", "offset")
        if d < 0.0:
            raise DesignError("generator.offset", f"must be >= 0 mm, got {d:g}")
        a = r_m + w0 - d
        quarter = 0.5 * math.pi * (r_m - d)  # a quarter of the base ellipse's perimeter
        # The offset adds 2 pi d to the perimeter, so the base ellipse has
        # perimeter 2 pi (r_m - d), which must exceed 4 a (the flat ellipse).
        if not (d < r_m and a < quarter):
            raise DesignError(
                "generator.offset",
                f"offset = {d:g} mm leaves no ellipse: the base ellipse would need semi-major "
                f"axis {a:g} mm and perimeter 2 pi (r_m - offset) = {4 * quarter:g} mm "
                "(it must exceed 4 x the semi-major axis)",
            )
        m = _solve_ellipe(quarter / a)
        for k, val in (("w0", w0), ("r_m", r_m), ("offset", d), ("a", a),
                       ("b", a * math.sqrt(1.0 - m)), ("_m", m), ("_E", float(ellipe(m)))):
            object.__setattr__(self, k, val)

    def _arc(self, t):
        """Arc length s of the neutral line from the +x vertex to ellipse parameter t, and ds/dt."""
        a, b, d = self.a, self.b, self.offset
        st, ct = np.sin(t), np.cos(t)
        g = np.sqrt((a * st) ** 2 + (b * ct) ** 2)  # |dE/dt| of the base ellipse
        # int_0^t g = a [E(m) - E(pi/2 - t | m)]  (substitute t -> pi/2 - u);
        # the offset adds d times the turning angle of the normal.
        s = a * (self._E - ellipeinc(_HALF_PI - t, self._m)) + d * np.arctan2(a * st, b * ct)
        return s, g + d * a * b / g**2

    def _quarter(self, psi):
        a, b, d, r = self.a, self.b, self.offset, self.r_m
        target = r * psi  # teeth placed by arc length (docs/models.md 3.1)
        t = psi.copy()
        for _ in range(60):
            s, ds = self._arc(t)
            step = (s - target) / ds
            t = np.clip(t - step, 0.0, _HALF_PI)
            if not np.any(np.abs(step) > NEWTON_TOL):
                # quadratic convergence: one more step reaches rounding level
                s, ds = self._arc(t)
                t = np.clip(t - (s - target) / ds, 0.0, _HALF_PI)
                break
        else:  # pragma: no cover - Newton on a smooth monotone arc length from t = psi
            raise GeometryError("Ellipse: inverse arc length did not converge")

        st, ct = np.sin(t), np.cos(t)
        g = np.sqrt((a * st) ** 2 + (b * ct) ** 2)
        nx, ny = b * ct / g, a * st / g  # outward unit normal
        px, py = a * ct + d * nx, b * st + d * ny
        cp, sp = np.cos(psi), np.sin(psi)
        w = px * cp + py * sp - r
        v = -px * sp + py * cp
        theta = np.arctan2(a * st, b * ct) - psi  # normal angle minus e_r angle
        kappa = 1.0 / (g**3 / (a * b) + d)  # curvature of the offset curve
        dtheta = r * kappa - 1.0
        sth = np.sin(theta)
        dw = v - r * sth
        dv = -2.0 * r * np.sin(0.5 * theta) ** 2 - w  # r_m (cos(theta) - 1) - w
        d2w = dv - r * np.cos(theta) * dtheta
        return w, dw, d2w, v, dv, theta, dtheta


# --------------------------------------------------------------------------
# registry


LAWS: dict[str, type[Law]] = {
    cls.name: cls for cls in (Harmonic, Disc, FourForce, Ellipse, ExternalRing)
}


def make_law(name, *, w0, r_m, n_waves=2, beta=None, offset=0.0) -> Law:
    """Build a deformation law from design-file values.

    Parameters
    ----------
    name : str
        One of :data:`LAWS` (``generator.law``).
    w0 : float
        W0, mm (``generator.w0_coef`` times the module).
    r_m : float
        Neutral-line radius, mm.
    n_waves : int, default 2
        ``drive.waves``; laws other than ``harmonic`` require 2.
    beta : float, optional
        Wrap half-angle / force angle, rad (``generator.beta_deg``); required
        by ``disc``, ``four_force`` and ``external_ring``, ignored otherwise.
    offset : float, default 0.0
        ``generator.offset``, mm (>= 0); used by ``ellipse`` only.

    Returns
    -------
    Law

    Raises
    ------
    DesignError
        Unknown name (the message lists the choices) or a parameter out of
        range (the message names the field and the rule).

    Examples
    --------
    >>> make_law("disc", w0=0.88, r_m=80.0, beta=np.radians(40.0)).name
    'disc'
    >>> make_law("cam", w0=0.88, r_m=80.0)
    Traceback (most recent call last):
    ...
    wgcad.errors.DesignError: generator.law: must be one of disc, ellipse, external_ring, four_force, harmonic, got 'cam'
    """
    if not isinstance(name, str) or name not in LAWS:
        choices = ", ".join(sorted(LAWS))
        raise DesignError("generator.law", f"must be one of {choices}, got {name!r}")
    off = _real(offset, "generator.offset", "offset")
    if off < 0.0:
        raise DesignError("generator.offset", f"must be >= 0 mm, got {off:g}")
    if name == "harmonic":
        return Harmonic(w0, r_m, n_waves)
    _check_two_waves(n_waves, name)
    if name == "ellipse":
        return Ellipse(w0, r_m, off)
    return LAWS[name](w0, r_m, beta)
