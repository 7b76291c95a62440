"""Deformation laws of the flexspline neutral line: w, v, theta and derivatives (docs/models.md 3), and coning along the axis.

One module per family of laws (``harmonic``, ``sectioned``: disc, external
ring and four-force cam, ``ellipse``) on the common base (``base``), and
``coning`` (W0 along a cup's axis); this module holds the registry that
builds a law from design-file values.
"""

from __future__ import annotations

import numpy as np  # noqa: F401  (the doctest of make_law uses it)

from wgcad.errors import DesignError

from .base import Law, RimState, check_two_waves, real_number
from .coning import coned_w0
from .ellipse import Ellipse
from .harmonic import Harmonic
from .sectioned import FF_BETA_HI, FF_BETA_LO, Disc, ExternalRing, FourForce  # noqa: F401  (the bands are tested)

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
    "coned_w0",
]

# --------------------------------------------------------------------------
# registry


LAWS: dict[str, type[Law]] = {cls.name: cls for cls in (Harmonic, Disc, FourForce, Ellipse, ExternalRing)}


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
    off = real_number(offset, "generator.offset", "offset")
    if off < 0.0:
        raise DesignError("generator.offset", f"must be >= 0 mm, got {off:g}")
    if name == "harmonic":
        return Harmonic(w0, r_m, n_waves)
    check_two_waves(n_waves, name)
    if name == "ellipse":
        return Ellipse(w0, r_m, off)
    return LAWS[name](w0, r_m, beta)
