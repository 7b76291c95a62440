"""Involute tooth geometry: thickness at any radius, flank points and the tangent root fillet (docs/models.md 2.1)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "inv",
    "pressure_angle_at",
    "half_angle_at",
    "involute_flank",
    "fillet_external",
    "fillet_internal",
]


def inv(alpha):
    """Involute function ``tan(a) - a``."""
    return np.tan(alpha) - alpha


def pressure_angle_at(r_base: float, radius):
    """Profile angle at ``radius``: ``cos(alpha_R) = r_base / R`` (docs/models.md 2.1)."""
    return np.arccos(np.clip(r_base / np.asarray(radius, dtype=float), -1.0, 1.0))


def half_angle_at(psi_base: float, r_base: float, radius):
    """Angular half-width at ``radius`` of a region bounded by two involutes.

    For an external tooth ``psi_base = s/(2r) + inv(alpha)`` and the result
    is half the tooth's angular thickness, ``s(R)/(2R)`` of docs/models.md 2.1; for
    an internal gear the same with the space width ``e`` gives half the
    space's angular width.
    """
    return psi_base - inv(pressure_angle_at(r_base, radius))


def involute_flank(psi_base: float, r_base: float, t) -> np.ndarray:
    """Points ``(n, 2)`` of the upper involute bounding a region of half-angle ``psi_base - inv``.

    ``t`` is the roll parameter (radius ``r_base*sqrt(1+t^2)``,
    ``inv(alpha_R) = t - atan(t)``). The region lies at smaller polar angle.
    """
    t = np.asarray(t, dtype=float)
    ang = psi_base - (t - np.arctan(t))
    rad = r_base * np.sqrt(1.0 + t * t)
    return np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=-1)


def fillet_external(psi_base: float, r_base: float, r_root: float, rho: float):
    """Root fillet of an external tooth: circle of radius ``rho`` tangent to the root circle and the flank.

    The flank is the upper involute of :func:`involute_flank` above the base
    circle and the radial line at angle ``psi_base`` below it (where
    ``r_root < r_base``). The fillet centre lies on the flank's offset by
    ``rho`` into the space; the offset of an involute is the same involute
    turned by ``rho / r_base`` (its normals are tangent to the base circle).

    Returns
    -------
    center : (2,) float
    center_angle : float
        Polar angle of the centre (and of the root tangent point).
    flank_point : (2,) float
        Tangent point on the flank.
    t_flank : float or None
        Roll parameter of the tangent point, None on the radial extension.
    """
    Rc = r_root + rho
    Lc2 = Rc * Rc - r_base * r_base
    if Lc2 >= rho * rho:
        # centre on the offset involute; string length Lc = r_base * t + rho
        Lc = np.sqrt(Lc2)
        ang_c = psi_base + rho / r_base - (Lc / r_base - np.arctan(Lc / r_base))
        t_f = (Lc - rho) / r_base
        flank_point = involute_flank(psi_base, r_base, np.array([t_f]))[0]
    else:
        # centre beside the radial extension of the flank below the base circle
        Rt = np.sqrt(Rc * Rc - rho * rho)
        ang_c = psi_base + np.arctan2(rho, Rt)
        t_f = None
        flank_point = np.array([Rt * np.cos(psi_base), Rt * np.sin(psi_base)])
    center = np.array([Rc * np.cos(ang_c), Rc * np.sin(ang_c)])
    return center, float(ang_c), flank_point, t_f


def fillet_internal(sigma_base: float, r_base: float, r_root: float, rho: float):
    """Root fillet of an internal gear, in the frame where the space is centred on angle 0.

    The space's upper boundary is the involute of :func:`involute_flank` with
    ``sigma_base = e/(2r) + inv(alpha)``; the gear material lies at larger
    angle. The fillet circle lies in the space, tangent internally to the
    root circle (centre radius ``r_root - rho``) and to the flank: its centre
    is on the involute offset by ``-rho``, i.e. turned by ``-rho / r_base``.

    Returns ``(center, center_angle, flank_point, t_flank)`` as
    :func:`fillet_external`, angles in the space-centred frame.
    """
    Rc = r_root - rho
    Lc = np.sqrt(Rc * Rc - r_base * r_base)
    ang_c = sigma_base - rho / r_base - (Lc / r_base - np.arctan(Lc / r_base))
    t_f = (Lc + rho) / r_base
    flank_point = involute_flank(sigma_base, r_base, np.array([t_f]))[0]
    center = np.array([Rc * np.cos(ang_c), Rc * np.sin(ang_c)])
    return center, float(ang_c), flank_point, float(t_f)
