"""Unit factors at the edges: wgcad computes in mm and radians and converts only where a figure is shown or read.

One definition of each factor (rad -> arcsec had been written four ways);
names say what they convert, e.g. ``ke_rad * ARCSEC_PER_RAD``.
"""

from __future__ import annotations

from math import pi

__all__ = ["ARCSEC_PER_RAD", "ARCMIN_PER_RAD", "UM_PER_MM"]

#: arcseconds in a radian (206264.806...)
ARCSEC_PER_RAD = 180.0 * 3600.0 / pi
#: arcminutes in a radian
ARCMIN_PER_RAD = 180.0 * 60.0 / pi
#: micrometres in a millimetre
UM_PER_MM = 1000.0
