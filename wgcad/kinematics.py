"""Gear ratios, rotations and external-deformation generator velocities (docs/models.md 1, 3.5)."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from wgcad.errors import DesignError
from wgcad.laws import Law

__all__ = ["gear_ratios", "flex_rotation", "RingVelocities", "ring_generator_velocities"]


def _teeth(value, field_name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise DesignError(field_name, f"must be a positive integer tooth count, got {value!r}")
    return int(value)


def gear_ratios(z_flex: int, z_rigid: int) -> dict[str, float]:
    """Gear ratios of a perfect strain-wave drive (docs/models.md 1, [S3 eq. 21-24]).

    Parameters
    ----------
    z_flex : int
        z_g, teeth of the flexspline (external teeth for internal deformation,
        internal teeth for external deformation).
    z_rigid : int
        z_b, teeth of the rigid gear.

    Returns
    -------
    dict
        ``"u_hg"``: omega_h / omega_g = -z_g / (z_b - z_g), rigid gear fixed,
        flexspline output; ``"u_hb"``: omega_h / omega_b = z_b / (z_b - z_g),
        flexspline fixed, rigid gear output. For external deformation
        (z_g > z_b) both signs flip.

    Raises
    ------
    DesignError
        Non-positive or equal tooth counts.

    Examples
    --------
    >>> gear_ratios(200, 202)
    {'u_hg': -100.0, 'u_hb': 101.0}
    >>> gear_ratios(300, 298)
    {'u_hg': 150.0, 'u_hb': -149.0}
    """
    z_g = _teeth(z_flex, "drive.z_flex")
    z_b = _teeth(z_rigid, "drive.z_rigid")
    if z_g == z_b:
        raise DesignError("drive.z_rigid", f"must differ from the flexspline's {z_g} teeth")
    dz = z_b - z_g
    # docs/models.md 1, gear ratios
    return {"u_hg": -z_g / dz, "u_hb": z_b / dz}


def flex_rotation(phi_h, z_flex: int, z_rigid: int) -> np.ndarray:
    """Flexspline rotation relative to the rigid gear: phi_g = phi_h / u_hg (docs/models.md 1).

    Parameters
    ----------
    phi_h : (...) float or array_like
        Generator rotation relative to the rigid gear, rad.
    z_flex, z_rigid : int
        Tooth counts z_g, z_b.

    Returns
    -------
    (...) float ndarray
        phi_g, rad, same shape as `phi_h`.

    Examples
    --------
    >>> float(flex_rotation(2 * np.pi, 200, 202) / (2 * np.pi))
    -0.01
    """
    u_hg = gear_ratios(z_flex, z_rigid)["u_hg"]
    return np.asarray(phi_h, dtype=np.float64) / u_hg


@dataclass(frozen=True, slots=True)
class RingVelocities:
    """Velocities of the flexspline and washers of an external ring generator (docs/models.md 3.5).

    Every field an array of phi's shape (read-only), speeds in mm/s (with
    omega_h in rad/s), dtheta_dt in rad/s.

    Attributes
    ----------
    phi : (...) float
        Angle from the generator major axis, rad.
    V_w, V_v : (...) float
        dw/dt and dv/dt of the neutral line.
    dtheta_dt : (...) float
        Angular speed of the rim cross-section.
    V_wK, V_vK : (...) float
        Radial and tangential speed of the outer-surface point K at h_c/2
        from the neutral line (w_K = w + h_c/2, v_K = v + (h_c/2) theta).
    V_d : (...) float
        Speed of every washer point, omega_h a_w (circular translation).
    V_dw, V_dv : (...) float
        Its projections a_w omega_h sin(phi), a_w omega_h cos(phi).
    V_sl : (...) float
        Sliding speed V_d - V_v.
    """

    phi: np.ndarray
    V_w: np.ndarray
    V_v: np.ndarray
    dtheta_dt: np.ndarray
    V_wK: np.ndarray
    V_vK: np.ndarray
    V_d: np.ndarray
    V_dw: np.ndarray
    V_dv: np.ndarray
    V_sl: np.ndarray

    def __post_init__(self):
        shape = np.shape(self.phi)
        for name in self.__dataclass_fields__:
            arr = np.array(np.broadcast_to(getattr(self, name), shape), dtype=np.float64)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)


def ring_generator_velocities(law: Law, phi, omega_h: float, h_c: float, a_w: float) -> RingVelocities:
    """Velocity fields of an external-deformation ring generator (docs/models.md 3.5).

    Follows [S3] as docs/models.md 3.5 writes it: phi = omega_h t, i.e. the angle
    of the observed flexspline point from the generator axis grows at
    omega_h, so d/dt = omega_h d/dphi. (A generator turning counter-clockwise
    past a flexspline point makes that point's phi *decrease*; pass a negative
    omega_h for that reading: every flexspline field then changes sign.) The
    flexspline's own rotation, omega_h / u_hg (1/150 of omega_h for 300/298),
    is neglected as in [S3].

    Parameters
    ----------
    law : Law
        Neutral-line law, normally :class:`~wgcad.laws.ExternalRing`.
    phi : (...) float or array_like
        Angles from the generator major axis, rad.
    omega_h : float
        Generator angular speed, rad/s.
    h_c : float
        Flexspline wall thickness, mm; K lies h_c/2 outside the neutral line.
    a_w : float
        Crank eccentricity of the washers (= centre distance), mm.

    Returns
    -------
    RingVelocities

    Examples
    --------
    >>> from wgcad.laws import ExternalRing
    >>> law = ExternalRing(w0=0.9, r_m=135.0, beta=np.radians(40.0))
    >>> vel = ring_generator_velocities(law, [0.0, 1.0], 210.0, 0.9, 0.9)
    >>> vel.V_d.tolist()
    [189.0, 189.0]
    """
    omega_h = float(omega_h)
    h_c, a_w = float(h_c), float(a_w)
    for name, val in (("omega_h", omega_h), ("h_c", h_c), ("a_w", a_w)):
        if not math.isfinite(val):
            raise DesignError(name, f"must be finite, got {val!r}")
    if h_c < 0.0:
        raise DesignError("h_c", f"wall thickness must be >= 0 mm, got {h_c:g}")
    if a_w < 0.0:
        raise DesignError("a_w", f"washer eccentricity must be >= 0 mm, got {a_w:g}")
    s = law.state(phi)
    phi = s.phi
    # docs/models.md 3.5: phi = omega_h t, so d/dt = omega_h d/dphi
    V_w = omega_h * s.dw
    V_v = omega_h * s.dv
    dtheta_dt = omega_h * s.dtheta
    # docs/models.md 3.5: w_K = w + h_c/2 (h_c constant), v_K = v + (h_c/2) theta
    V_wK = V_w
    V_vK = V_v + 0.5 * h_c * dtheta_dt
    # docs/models.md 3.5: washers in circular translation at the generator speed
    # (omega_d = omega_h); projections and V_sl exactly as written there
    # (V_sl = V_d - V_v, not V_dv - V_v: we keep the source's definition).
    V_d = np.full_like(phi, omega_h * a_w)
    V_dw = a_w * omega_h * np.sin(phi)
    V_dv = a_w * omega_h * np.cos(phi)
    V_sl = V_d - V_v
    return RingVelocities(phi, V_w, V_v, dtheta_dt, V_wK, V_vK, V_d, V_dw, V_dv, V_sl)
