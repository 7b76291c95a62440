"""Analytic double-flank and single-flank error model of eccentric gears in wave engagement (docs/models.md 6.1).

Sign and phase conventions (docs/models.md 6.1 derives them). Generator frame,
major axis on +x; a mesh zone is the direction ``zone`` (rad) in that frame.
``theta_flex`` and ``theta_rigid`` are the angles by which the flexspline
("conditional wheel" y of [S2]) and the rigid gear (b) have turned relative
to the generator, each counted from the direction of its own geometric
eccentricity (the rigid gear's from the opposite direction, so that the
terms of both gears add, as [S2] writes them). With ``t_j = theta_j - zone``:

* geometric eccentricity ``e_jr`` moves gear j's teeth in the zone by
  ``e_jr cos t_j`` radially and ``e_jr sin t_j`` tangentially;
* kinematic eccentricity ``e_jk`` (first harmonic of the accumulated pitch
  deviation, measured along the line of action) shifts the tooth in the zone
  by ``e_jk sin(t_j + psi_j)`` along the line of action.

A flank of profile angle ``alpha`` then moves along its normal by
``dn_left = dr sin(alpha) + dt cos(alpha) + k`` (working, "left" flank of
[S2]) and ``dn_right = dr sin(alpha) - dt cos(alpha) - k`` (the other), and
the mesh takes this up at the working pressure angle ``alpha_w``:

* double-flank (both flanks in contact): ``dR sin(aw) +- dT cos(aw) = dn_left, dn_right``;
* single-flank (one flank in contact): ``dR = dn / sin(aw)`` or ``dT = +-dn / cos(aw)``.

Lengths mm, angles rad inside; :func:`flank_error_table` and
:func:`write_flank_error_csv` are the edge (degrees, micrometres).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

import numpy as np

from wgcad.errors import DesignError

__all__ = [
    "ENGAGEMENTS",
    "Eccentricities",
    "FlankErrors",
    "gear_angles",
    "flank_errors",
    "flank_errors_over_rotation",
    "flank_error_table",
    "write_flank_error_csv",
    "drive_displacements",
    "drive_flank_errors",
]

#: engagement types: both flanks in contact, or one flank (left: the working
#: flank of [S2]; right: the other)
ENGAGEMENTS = ("double", "single_left", "single_right")


def _real(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise DesignError(name, f"must be a finite real number, got {value!r}")
    return float(value)


@dataclass(frozen=True, slots=True)
class Eccentricities:
    """Eccentricities of both gears and the phases of the kinematic ones. Lengths mm, angles rad.

    Attributes
    ----------
    flex_geometric, rigid_geometric : float
        e_yr, e_br >= 0: offset of the pitch circle's centre from the axis of
        rotation, mm.
    flex_kinematic, rigid_kinematic : float
        e_yk, e_bk >= 0: amplitude of the first harmonic of the accumulated
        pitch deviation, along the line of action, mm (half the tooth-to-tooth
        kinematic error it causes over a turn).
    flex_phase, rigid_phase : float
        psi_y, psi_b: phase of each kinematic eccentricity relative to the
        same gear's geometric one, rad.
    """

    flex_geometric: float = 0.0
    flex_kinematic: float = 0.0
    rigid_geometric: float = 0.0
    rigid_kinematic: float = 0.0
    flex_phase: float = 0.0
    rigid_phase: float = 0.0

    def __post_init__(self):
        for f in fields(self):
            val = _real(getattr(self, f.name), f"eccentricity.{f.name}")
            if not f.name.endswith("_phase") and val < 0.0:
                raise DesignError(
                    f"eccentricity.{f.name}", f"must be >= 0 mm (the phase carries the direction), got {val:g}"
                )
            object.__setattr__(self, f.name, val)


@dataclass(frozen=True, slots=True)
class FlankErrors:
    """Radial and tangential mesh displacements, mm, read-only arrays of one shape.

    Attributes
    ----------
    dR : (...) float
        Radial displacement that takes up the errors, mm (positive: the
        flexspline's teeth moved outward relative to the rigid gear's, i.e.
        deeper into mesh for internal deformation).
    dT : (...) float
        Tangential displacement that takes them up, mm, at the pitch circle.
    """

    dR: np.ndarray
    dT: np.ndarray

    def __post_init__(self):
        for name in ("dR", "dT"):
            arr = np.array(getattr(self, name), dtype=np.float64)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)


def _angle(value, name: str, lo: float = 0.0, hi: float = 0.5 * math.pi) -> float:
    val = _real(value, name)
    if not lo < val < hi:
        raise DesignError(
            name, f"must lie in ({math.degrees(lo):g}, {math.degrees(hi):g}) degrees, got {math.degrees(val):.10g}"
        )
    return val


def gear_angles(phi_h, z_flex: int, z_rigid: int, flex_start: float = 0.0, rigid_start: float = 0.0):
    """Angles of the flexspline and the rigid gear relative to the generator (docs/models.md 6.1).

    Teeth of both gears pass a mesh zone at the same rate, so relative to the
    generator the rigid gear turns by ``-phi_h`` and the flexspline by
    ``phi_h / u_hg - phi_h = -phi_h z_b / z_g`` (docs/models.md 1): the
    flexspline's terms have order ``z_b / z_g`` per generator turn, the rigid
    gear's order 1. Both repeat after ``z_g / gcd(z_g, z_b)`` generator turns
    (one flexspline revolution, ``|u_hg|`` turns, when ``gcd(z_g, z_b) = |z_b - z_g|``,
    e.g. 200/202).

    Parameters
    ----------
    phi_h : (...) float or array_like
        Generator angle relative to the rigid gear, rad.
    z_flex, z_rigid : int
        Tooth counts z_g, z_b (either order: internal or external deformation).
    flex_start, rigid_start : float
        The angles at ``phi_h = 0`` (assembly phases of the geometric
        eccentricities), rad.

    Returns
    -------
    theta_flex, theta_rigid : (...) float ndarray

    Examples
    --------
    >>> tf, tr = gear_angles(2 * np.pi, 200, 202)
    >>> round(float(tf / (2 * np.pi)), 12), round(float(tr / (2 * np.pi)), 12)
    (-1.01, -1.0)
    """
    for name, z in (("drive.z_flex", z_flex), ("drive.z_rigid", z_rigid)):
        if isinstance(z, bool) or not isinstance(z, numbers.Integral) or z < 1:
            raise DesignError(name, f"must be a positive integer tooth count, got {z!r}")
    if z_flex == z_rigid:
        raise DesignError("drive.z_rigid", f"must differ from the flexspline's {z_flex} teeth")
    phi_h = np.asarray(phi_h, dtype=np.float64)
    theta_rigid = _real(rigid_start, "rigid_start") - phi_h
    theta_flex = _real(flex_start, "flex_start") - phi_h * (z_rigid / z_flex)
    return theta_flex, theta_rigid


def flank_errors(
    theta_flex,
    theta_rigid,
    ecc: Eccentricities,
    alpha: float,
    alpha_w: float,
    engagement: str = "double",
    zone: float = 0.0,
) -> FlankErrors:
    """Radial and tangential displacements dR, dT of [S2] (docs/models.md 6.1), vectorised.

    Parameters
    ----------
    theta_flex, theta_rigid : (...) float or array_like
        Gear angles relative to the generator (:func:`gear_angles`), rad;
        broadcast together.
    ecc : Eccentricities
    alpha : float
        Profile angle of the teeth, rad, in (0, 90 deg).
    alpha_w : float
        Working pressure angle of the engagement, rad, in (0, 90 deg).
    engagement : {"double", "single_left", "single_right"}
        Both flanks in contact, or one.
    zone : float, default 0
        Direction of the mesh zone in the generator frame, rad (0: the major
        axis; pi: the second zone of a two-wave drive).

    Returns
    -------
    FlankErrors

    Examples
    --------
    >>> e = Eccentricities(flex_geometric=0.01)
    >>> r = flank_errors(0.0, 0.0, e, np.radians(20), np.radians(20))
    >>> round(float(r.dR), 12), round(float(r.dT), 12)
    (0.01, 0.0)
    """
    if engagement not in ENGAGEMENTS:
        raise DesignError("engagement", f"must be one of {', '.join(ENGAGEMENTS)}, got {engagement!r}")
    if not isinstance(ecc, Eccentricities):
        raise TypeError(f"ecc must be an Eccentricities, got {type(ecc).__name__}")
    alpha = _angle(alpha, "tooth.pressure_angle_deg")
    alpha_w = _angle(alpha_w, "working_pressure_angle_deg")
    zone = _real(zone, "zone")
    ty = np.asarray(theta_flex, dtype=np.float64) - zone
    tb = np.asarray(theta_rigid, dtype=np.float64) - zone
    ty, tb = np.broadcast_arrays(ty, tb)
    # relative displacement of the flexspline tooth against the rigid one (docs/models.md 6.1)
    dr = ecc.flex_geometric * np.cos(ty) + ecc.rigid_geometric * np.cos(tb)
    dt = ecc.flex_geometric * np.sin(ty) + ecc.rigid_geometric * np.sin(tb)
    kin = ecc.flex_kinematic * np.sin(ty + ecc.flex_phase) + ecc.rigid_kinematic * np.sin(tb + ecc.rigid_phase)
    return _take_up(dr, dt, kin, alpha, alpha_w, engagement)


def _take_up(dr, dt, kin, alpha: float, alpha_w: float, engagement: str) -> FlankErrors:
    """The mesh's radial and tangential motion that takes up a relative displacement of the teeth in a zone:
    ``dr`` radial, ``dt`` tangential (geometric), ``kin`` along the line of action (docs/models.md 6.1)."""
    sa, ca = math.sin(alpha), math.cos(alpha)
    sw, cw = math.sin(alpha_w), math.cos(alpha_w)
    if engagement == "double":
        # [S2] double-flank: the kinematic terms cancel from dR
        return FlankErrors(dR=(sa / sw) * dr, dT=(ca * dt + kin) / cw)
    if engagement == "single_left":
        dn = sa * dr + ca * dt + kin  # = e_r sin(t + alpha) + e_k sin(t + psi) per gear, [S2]
        return FlankErrors(dR=dn / sw, dT=dn / cw)
    dn = sa * dr - ca * dt - kin
    return FlankErrors(dR=dn / sw, dT=-dn / cw)


def drive_displacements(drive, imp, phi_h, zone: float = 0.0):
    """The relative displacement of the flexspline's tooth against the rigid gear's in a mesh zone of an imperfect
    drive, split as [S2] does (docs/models.md 6.1): ``dr``, ``dt`` from the translations (both gears'
    eccentricities, the cam offsets), ``kin`` from the run-outs along the line of action.

    Everything is read from the drive's own error field (:mod:`wgcad.placement.imperfect`): the teeth of the
    zone at generator angle ``phi_h`` (rad, rigid gear fixed) are the flexspline's tooth at its angle
    ``zone + phi_h - phi_g`` and the rigid gear's at ``zone + phi_h``; a run-out ``F`` deviates a tooth along
    the pitch circle by ``(F/2) sin(a + xi)``, which is ``cos(alpha)`` of that along the line of action
    ([S2]'s ``e_k``); a translation ``D`` of the flexspline's teeth relative to the rigid ones is ``D . e_r``
    radially and ``D . e_t`` tangentially in the zone ([S2]'s geometric terms). The cam offsets move the
    flexspline's teeth with the rim: the cam-borne one is constant in the zone (a constant term), the
    stationary one turns against it once a generator turn (as a rigid-gear eccentricity), the
    flexspline-borne one with the flexspline.

    Returns
    -------
    dr, dt, kin : (...) float, mm
    """
    from ..placement.imperfect import cam_offset, rigid_translation

    d = drive.design.drive
    phi_h = np.asarray(phi_h, dtype=np.float64)
    phi_g = phi_h * (d.z_flex - d.z_rigid) / d.z_flex  # phi_h / u_hg, rigid gear fixed (docs/models.md 1)
    Z = zone + phi_h  # the zone's direction in the rigid gear's frame
    a_f = Z - phi_g  # the flexspline tooth there, in the flexspline's own frame
    g = imp.flex_install
    T_f = imp.flex_ecc * np.stack(
        [np.cos(imp.flex_ecc_phase + g + phi_g), np.sin(imp.flex_ecc_phase + g + phi_g)], axis=-1
    )
    D = T_f + cam_offset(imp, phi_h, phi_g) - rigid_translation(imp)
    er = np.stack([np.cos(Z), np.sin(Z)], axis=-1)
    et = np.stack([-np.sin(Z), np.cos(Z)], axis=-1)
    dr = (D * er).sum(axis=-1)
    dt = (D * et).sum(axis=-1)
    tan_f = 0.5 * imp.flex_runout * np.sin(a_f - g + imp.flex_runout_phase)
    tan_b = 0.5 * imp.rigid_runout * np.sin(Z - imp.rigid_install + imp.rigid_runout_phase)
    alpha = float(np.deg2rad(drive.design.tooth.pressure_angle_deg))
    return dr, dt, (tan_f - tan_b) * math.cos(alpha)


def drive_flank_errors(
    drive, imp, phi_h, engagement: str = "double", zone: float = 0.0, alpha_w: float | None = None
) -> FlankErrors:
    """[S2]'s ``dR``, ``dT`` of an imperfect drive in a mesh zone (:func:`drive_displacements`), docs/models.md 6.1.

    ``alpha_w`` defaults to the profile angle (the teeth of both gears are cut to one rack)."""
    if engagement not in ENGAGEMENTS:
        raise DesignError("engagement", f"must be one of {', '.join(ENGAGEMENTS)}, got {engagement!r}")
    alpha = float(np.deg2rad(drive.design.tooth.pressure_angle_deg))
    dr, dt, kin = drive_displacements(drive, imp, phi_h, zone)
    return _take_up(dr, dt, kin, alpha, alpha if alpha_w is None else alpha_w, engagement)


def flank_errors_over_rotation(
    phi_h,
    z_flex: int,
    z_rigid: int,
    ecc: Eccentricities,
    alpha: float,
    alpha_w: float,
    flex_start: float = 0.0,
    rigid_start: float = 0.0,
    zone: float = 0.0,
) -> dict[str, FlankErrors]:
    """:func:`flank_errors` of every engagement type over generator angles ``phi_h`` (rad, relative to the rigid gear).

    Returns
    -------
    dict
        ``{engagement: FlankErrors}`` for each of :data:`ENGAGEMENTS`.
    """
    ty, tb = gear_angles(phi_h, z_flex, z_rigid, flex_start, rigid_start)
    return {e: flank_errors(ty, tb, ecc, alpha, alpha_w, e, zone) for e in ENGAGEMENTS}


def flank_error_table(
    generator_angle_deg,
    *,
    z_flex: int,
    z_rigid: int,
    pressure_angle_deg: float,
    working_pressure_angle_deg: float,
    flex_geometric_um: float = 0.0,
    flex_kinematic_um: float = 0.0,
    rigid_geometric_um: float = 0.0,
    rigid_kinematic_um: float = 0.0,
    flex_phase_deg: float = 0.0,
    rigid_phase_deg: float = 0.0,
    flex_start_deg: float = 0.0,
    rigid_start_deg: float = 0.0,
    zone_deg: float = 0.0,
):
    """Both engagement types side by side, at the edge: degrees and micrometres in, a header and rows out.

    Returns
    -------
    header : list of str
        ``generator_angle_deg``, then ``dR_um`` and ``dT_um`` of each
        engagement type (``double_dR_um``, ...).
    rows : list of list of float
    """
    ecc = Eccentricities(
        flex_geometric=1e-3 * _real(flex_geometric_um, "flex_geometric_um"),
        flex_kinematic=1e-3 * _real(flex_kinematic_um, "flex_kinematic_um"),
        rigid_geometric=1e-3 * _real(rigid_geometric_um, "rigid_geometric_um"),
        rigid_kinematic=1e-3 * _real(rigid_kinematic_um, "rigid_kinematic_um"),
        flex_phase=math.radians(_real(flex_phase_deg, "flex_phase_deg")),
        rigid_phase=math.radians(_real(rigid_phase_deg, "rigid_phase_deg")),
    )
    deg = np.atleast_1d(np.asarray(generator_angle_deg, dtype=np.float64)).ravel()
    res = flank_errors_over_rotation(
        np.radians(deg),
        z_flex,
        z_rigid,
        ecc,
        math.radians(_real(pressure_angle_deg, "pressure_angle_deg")),
        math.radians(_real(working_pressure_angle_deg, "working_pressure_angle_deg")),
        math.radians(_real(flex_start_deg, "flex_start_deg")),
        math.radians(_real(rigid_start_deg, "rigid_start_deg")),
        math.radians(_real(zone_deg, "zone_deg")),
    )
    header = ["generator_angle_deg"]
    cols = [deg]
    for e in ENGAGEMENTS:
        header += [f"{e}_dR_um", f"{e}_dT_um"]
        cols += [1e3 * res[e].dR, 1e3 * res[e].dT]
    return header, np.stack(cols, axis=1).tolist()


def write_flank_error_csv(path, header, rows) -> None:
    """Write :func:`flank_error_table`'s header and rows as CSV, atomically (``%.9g``, ``\\n`` line ends)."""
    from wgcad.atomic import atomic_write  # I/O at the edge

    lines = [",".join(header)]
    lines += [",".join(f"{float(x):.9g}" for x in row) for row in rows]
    atomic_write(path, ("\n".join(lines) + "\n").encode("ascii"))
