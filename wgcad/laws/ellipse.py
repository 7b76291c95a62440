"""The exact elliptical cam: an ellipse offset outward (docs/models.md 3.6)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from wgcad.constants import NEWTON_TOL
from wgcad.errors import DesignError, GeometryError

from .base import HALF_PI, TwoWaveLaw, check_w0_rm, real_number

__all__ = ["Ellipse", "ellipe", "ellipeinc"]

# --------------------------------------------------------------------------
# exact elliptical cam


def ellipe(m):
    """Complete elliptic integral of the second kind (scipy.special, imported on first use)."""
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


@dataclass(frozen=True, slots=True)
class Ellipse(TwoWaveLaw):
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
    tooth_offset: float = 0.0
    n_waves: int = field(default=2, init=False)
    a: float = field(init=False)
    b: float = field(init=False)
    _m: float = field(init=False, repr=False, compare=False)
    _E: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        w0, r_m = check_w0_rm(self.w0, self.r_m)
        d = real_number(self.offset, "generator.offset", "offset")
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
        for k, val in (
            ("w0", w0),
            ("r_m", r_m),
            ("offset", d),
            ("a", a),
            ("b", a * math.sqrt(1.0 - m)),
            ("_m", m),
            ("_E", float(ellipe(m))),
        ):
            object.__setattr__(self, k, val)

    def _arc(self, t):
        """Arc length s of the neutral line from the +x vertex to ellipse parameter t, and ds/dt."""
        a, b, d = self.a, self.b, self.offset
        st, ct = np.sin(t), np.cos(t)
        g = np.sqrt((a * st) ** 2 + (b * ct) ** 2)  # |dE/dt| of the base ellipse
        # int_0^t g = a [E(m) - E(pi/2 - t | m)]  (substitute t -> pi/2 - u);
        # the offset adds d times the turning angle of the normal.
        s = a * (self._E - ellipeinc(HALF_PI - t, self._m)) + d * np.arctan2(a * st, b * ct)
        return s, g + d * a * b / g**2

    def _quarter(self, psi):
        a, b, d, r = self.a, self.b, self.offset, self.r_m
        target = r * psi  # teeth placed by arc length (docs/models.md 3.1)
        t = psi.copy()
        for _ in range(60):
            s, ds = self._arc(t)
            step = (s - target) / ds
            t = np.clip(t - step, 0.0, HALF_PI)
            if not np.any(np.abs(step) > NEWTON_TOL):
                # quadratic convergence: one more step reaches rounding level
                s, ds = self._arc(t)
                t = np.clip(t - (s - target) / ds, 0.0, HALF_PI)
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
