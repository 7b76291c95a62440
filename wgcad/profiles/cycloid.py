"""Cycloidal teeth: exact epi/hypocycloids on the pitch circle and the rack approximation of [S1] (docs/models.md 2.2)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "epicycloid",
    "hypocycloid",
    "roll_angle_at_radius",
    "exact_half_angle",
    "rack_half_thickness",
    "rack_half_angle",
]


def epicycloid(r: float, rho: float, phi) -> np.ndarray:
    """Point ``(n, 2)`` traced by a circle of radius ``rho`` rolling outside the circle ``r``.

    Starts at ``(r, 0)`` (cusp on the pitch circle) for roll angle 0 and
    rolls toward positive polar angle; the apex ``r + 2 rho`` is at
    ``phi = pi``, polar angle ``pi rho / r``.
    """
    phi = np.asarray(phi, dtype=float)
    th = rho * phi / r
    x = (r + rho) * np.cos(th) - rho * np.cos(th + phi)
    y = (r + rho) * np.sin(th) - rho * np.sin(th + phi)
    return np.stack([x, y], axis=-1)


def hypocycloid(r: float, rho: float, phi) -> np.ndarray:
    """Point ``(n, 2)`` traced by a circle of radius ``rho`` rolling inside the circle ``r``.

    Starts at ``(r, 0)`` for roll angle 0, rolls toward positive polar angle;
    the lowest point ``r - 2 rho`` is at ``phi = pi``.
    """
    phi = np.asarray(phi, dtype=float)
    th = rho * phi / r
    x = (r - rho) * np.cos(th) + rho * np.cos(th - phi)
    y = (r - rho) * np.sin(th) + rho * np.sin(th - phi)
    return np.stack([x, y], axis=-1)


def roll_angle_at_radius(r: float, rho: float, radius, epi: bool):
    """Roll angle in ``[0, pi]`` at which the epi/hypocycloid reaches ``radius``.

    From ``|P|^2 = (r +- rho)^2 + rho^2 -+ 2 rho (r +- rho) cos(phi)``.
    """
    radius = np.asarray(radius, dtype=float)
    c = r + rho if epi else r - rho
    cosphi = (c * c + rho * rho - radius * radius) / (2.0 * rho * c)
    if not epi:
        cosphi = -cosphi
    # at the pitch circle and at the reach (r +- 2 rho) the roll angle is 0 or pi
    # exactly; arccos of a cosine rounded 1e-16 off +-1 is 1.5e-8 rad off, which
    # left a 0.06 nm sliver of root arc on every tooth. Within 1e-13
    # of +-1 the curve is tangent to that circle: snapping moves it < 1e-13 mm.
    cosphi = np.where(np.abs(cosphi) > 1.0 - 1e-13, np.sign(cosphi), cosphi)
    return np.arccos(np.clip(cosphi, -1.0, 1.0))


def exact_half_angle(r: float, rho: float, radius, tooth_inside: bool):
    """Half angular thickness of the exact cycloidal tooth at ``radius``.

    The tooth is centred on angle 0 with its pitch points at ``+-pi/(2z)``,
    i.e. ``+-pi rho / r`` (``p = 4 pi rho``).

    ``tooth_inside=False``: external gear, addendum (``R > r``) an
    epicycloid, dedendum a hypocycloid. ``tooth_inside=True``: internal
    gear, the tooth's addendum lies inside the pitch circle (hypocycloid),
    its dedendum outside (epicycloid).
    """
    radius = np.asarray(radius, dtype=float)
    q = np.pi * rho / r  # pitch-point half angle = gamma/4
    out = np.empty_like(radius)
    above = radius >= r
    for sel, epi in ((above, True), (~above, False)):
        if not np.any(sel):
            continue
        phi = roll_angle_at_radius(r, rho, radius[sel], epi)
        p = epicycloid(r, rho, phi) if epi else hypocycloid(r, rho, phi)
        ang = np.arctan2(p[..., 1], p[..., 0])  # >= 0: rolled toward +angle
        # addendum flanks lean toward the tooth centre, dedendum flanks away
        toward_centre = (epi and not tooth_inside) or ((not epi) and tooth_inside)
        out[sel] = q - ang if toward_centre else q + ang
    return out


def rack_half_thickness(rho: float, height, addendum_side) -> np.ndarray:
    """Half tooth thickness of the rack approximation at ``height`` from the pitch line (docs/models.md 2.2).

    ``x_M = rho (phi - sin phi - pi)``, ``y_M = rho (1 - cos phi)``; on the
    addendum side ``s = 2|x_M|``, on the dedendum side
    ``s = 2 (2 pi rho - |x_M|)`` (the corrected, continuous form).
    """
    h = np.abs(np.asarray(height, dtype=float))
    phi = np.arccos(np.clip(1.0 - h / rho, -1.0, 1.0))
    xm = np.abs(rho * (phi - np.sin(phi) - np.pi))
    return np.where(addendum_side, xm, 2.0 * np.pi * rho - xm)


def rack_half_angle(r: float, rho: float, radius, tooth_inside: bool):
    """Half angular thickness ``s(R)/(2R)`` from the rack approximation, pitch point at ``r``."""
    radius = np.asarray(radius, dtype=float)
    addendum_side = (radius < r) if tooth_inside else (radius > r)
    return rack_half_thickness(rho, radius - r, addendum_side) / radius
