"""Coning of a cup flexspline: the deformation amplitude along the axis (docs/models.md 3.1)."""

from __future__ import annotations

import numpy as np

from wgcad.errors import DesignError

from .base import real_number

__all__ = ["coned_w0"]


def coned_w0(w0, z, *, length, z_h):
    """Deformation amplitude at axial positions z of a cup flexspline.

    The rim pivots about the diaphragm, so the amplitude falls linearly from
    the open end to zero at the diaphragm:
    W0(z) = W0 (l - z) / (l - z_h)   (docs/models.md 3.1, coning).

    Parameters
    ----------
    w0 : float
        W0, mm: amplitude at the generator's centre line z = z_h.
    z : (...) float or array_like
        Axial positions, mm, z = 0 at the open end, 0 <= z <= length.
    length : float
        l, mm: distance from the open end to the diaphragm (> z_h).
    z_h : float
        Axial position of the generator's centre line, mm, 0 <= z_h < length.

    Returns
    -------
    (...) float ndarray
        W0(z) in mm, same shape as `z` (read-only).

    Raises
    ------
    DesignError
        Non-positive W0, length <= z_h, z_h < 0, or z outside [0, length].

    Examples
    --------
    >>> coned_w0(1.0, [0.0, 10.0, 160.0], length=160.0, z_h=10.0).tolist()
    [1.0666666666666667, 1.0, 0.0]
    """
    w0 = real_number(w0, "generator.w0_coef", "W0 = w0_coef * module")
    if w0 <= 0.0:
        raise DesignError("generator.w0_coef", f"W0 = w0_coef * module must be > 0 mm, got {w0:g} mm")
    length = real_number(length, "generator.cone_length", "length")
    z_h = real_number(z_h, "generator.generator_z", "z_h")
    if length <= 0.0:
        raise DesignError("generator.cone_length", f"must be > 0 mm, got {length:g}")
    if z_h < 0.0:
        raise DesignError("generator.generator_z", f"must be >= 0 mm (z = 0 is the open end), got {z_h:g}")
    if length <= z_h:
        raise DesignError(
            "generator.cone_length",
            f"must exceed the generator position z_h = {z_h:g} mm, got {length:g} mm",
        )
    z = np.array(z, dtype=np.float64)
    if z.size and not (np.all(np.isfinite(z)) and z.min() >= 0.0 and z.max() <= length):
        raise DesignError(
            "generator.cone_length",
            f"cross-sections must lie on the flexspline, 0 <= z <= length = {length:g} mm; "
            f"got z in [{z.min():g}, {z.max():g}] mm",
        )
    # docs/models.md 3.1, coning; the ratio first so that W0(z_h) == W0 exactly
    out = np.asarray(w0 * ((length - z) / (length - z_h)))
    out.flags.writeable = False
    return out
