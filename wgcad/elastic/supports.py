"""The members' rigid-body freedoms and what holds them: the flexspline on its cup, diaphragm and output bearing, the
rigid gear in its seat, the cam on its shaft; the cup's bending and twist along the face (docs/models.md 4.2).

Every contact of the load model (a tooth pair, a ball) acts in a *plane* along the drive's axis: the sections of
the face width and the ball plane. Its linearised gap closes by ``A3 . (dx, dy, rot)`` when the rim there moves
by ``(dx, dy, rot)`` against the rigid gear (``A3``, the contact's rim row, docs/models.md 4.1); a ball's gap also
by ``n . c`` when the cam moves by ``c``. What moves the rim at a plane is, in the spatial model,

* the flexspline's rigid-body freedoms: its rotation (free: the output torque balances it), the cup base's
  translation on the output bearing, and its tilt about the diaphragm, which moves a plane by the tilt times its
  distance from the diaphragm;
* the cup wall's own bending and shear between the diaphragm and the toothed rim (a field: a compliance between
  planes) and its twist (the torque of each plane runs through the wall to the diaphragm);
* minus the rigid gear's translation and tilt about its seat (tooth contacts only);

and in the planar model one rigid motion for every plane, held by the equivalent stiffnesses at the generator's
centre plane, the cup's twist added to the wind-up in series. A freedom of stiffness 0 is free (an equality of
the contact problem), ``inf`` held (dropped), anything between sprung (docs/models.md 4.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import pi

import numpy as np
from numpy.polynomial.legendre import leggauss

from ..design.parts import diaphragm_geometry

__all__ = [
    "Motion",
    "Supports",
    "build_supports",
    "plate_tilt_stiffness",
    "tube_lateral_compliance",
    "twist_compliance",
    "FREEDOMS_SPATIAL",
    "FREEDOMS_PLANAR",
]

#: shear coefficient of a thin-walled tube in bending (Timoshenko): half the wall's area carries the shear
_KAPPA_TUBE = 0.5
#: the spatial model's freedoms: the flexspline's rotation, translation and tilt (as the translation it gives per
#: mm from the diaphragm), the rigid gear's translation and tilt (per mm from its seat), the cam's translation
FREEDOMS_SPATIAL = (
    "rot",
    "flex_x",
    "flex_y",
    "flex_tilt_x",
    "flex_tilt_y",
    "rigid_x",
    "rigid_y",
    "rigid_tilt_x",
    "rigid_tilt_y",
    "cam_x",
    "cam_y",
)
FREEDOMS_PLANAR = ("rot", "flex_x", "flex_y", "rigid_x", "rigid_y", "cam_x", "cam_y")


def plate_tilt_stiffness(r_i: float, r_o: float, h: float, E: float, nu: float) -> float:
    """Moment per radian that tilts an annular plate, clamped at ``r_i``, by a rigid ring joined at ``r_o``, N mm/rad.

    The plate's deflection under a tilt ``phi`` of the ring is ``W(r) cos(theta)`` with Michell's ``n = 1``
    solution of the biharmonic equation, ``W = A r + B r^3 + C / r + D r ln r``, clamped at the hub
    (``W = W' = 0``) and following the ring at its edge (``W = phi r_o``, ``W' = phi``: a rigid joint). The
    stiffness is twice its bending energy per ``phi^2`` (docs/models.md 4.2).
    """
    if not (0.0 < r_i < r_o):
        return np.inf
    basis = [
        (lambda r: r, lambda r: 1.0, lambda r: 0.0),
        (lambda r: r**3, lambda r: 3.0 * r**2, lambda r: 6.0 * r),
        (lambda r: 1.0 / r, lambda r: -1.0 / r**2, lambda r: 2.0 / r**3),
        (lambda r: r * np.log(r), lambda r: np.log(r) + 1.0, lambda r: 1.0 / r),
    ]
    M = np.array(
        [[b[0](r_i) for b in basis], [b[1](r_i) for b in basis], [b[0](r_o) for b in basis], [b[1](r_o) for b in basis]]
    )
    c = np.linalg.solve(M, np.array([0.0, 0.0, r_o, 1.0]))
    x, w = leggauss(64)
    r = 0.5 * (r_o - r_i) * x + 0.5 * (r_o + r_i)
    W = sum(ci * b[0](r) for ci, b in zip(c, basis))
    W1 = sum(ci * b[1](r) for ci, b in zip(c, basis))
    W2 = sum(ci * b[2](r) for ci, b in zip(c, basis))
    lap = W2 + W1 / r - W / r**2
    cross = W2 * (W1 / r - W / r**2) - (W1 / r - W / r**2) ** 2
    D = E * h**3 / (12.0 * (1.0 - nu**2))
    energy = 0.5 * D * pi * float(np.sum(w * (lap**2 - 2.0 * (1.0 - nu) * cross) * r) * 0.5 * (r_o - r_i))
    return 2.0 * energy


def tube_lateral_compliance(x: np.ndarray, length: float, EI: float, kGA: float) -> np.ndarray:
    """Lateral compliance ``(P, P)`` (mm/N) between points ``x`` (mm from the clamped base) of a thin tube of
    ``length`` clamped at its base, stiff beyond (the toothed rim): Euler-Bernoulli bending plus Timoshenko shear.

    ``c(x, x') = int_0^u (x - s)(x' - s) ds / EI + u / kGA`` with ``u = min(x, x', length)``.
    """
    x = np.asarray(x, dtype=float)
    if length <= 0.0:
        return np.zeros((len(x), len(x)))
    a, b = x[:, None], x[None, :]
    u = np.minimum(np.minimum(a, b), length)
    u = np.maximum(u, 0.0)
    bend = (a * b * u - 0.5 * (a + b) * u**2 + u**3 / 3.0) / EI
    return bend + u / kGA


def twist_compliance(z: np.ndarray, z_end: float, pieces) -> np.ndarray:
    """Torsional compliance ``(P, P)`` (rad per N mm) between planes ``z``: a torque at ``z_q`` twists the wall from
    there to ``z_end`` (the diaphragm), so the plane ``z_p`` turns by ``int_{max(z_p, z_q)}^{z_end} dz / GJ``.

    ``pieces``: ``[(z0, z1, GJ), ...]`` covering the length, N mm^2.
    """
    z = np.asarray(z, dtype=float)
    m = np.maximum(z[:, None], z[None, :])
    out = np.zeros_like(m)
    for z0, z1, GJ in pieces:
        lo = np.clip(m, z0, z1)
        out += (z1 - lo) / GJ
    return out


def _series(*k: float) -> float:
    """Stiffnesses in series (0 if any is 0, inf if all are)."""
    c = sum(1.0 / x if x > 0 else np.inf for x in k)
    return 0.0 if np.isinf(c) else (np.inf if c == 0 else 1.0 / c)


@dataclass(frozen=True)
class Motion:
    """Where the members stand at every plane (housing frame, generator's axes), mm and rad.

    Attributes
    ----------
    rim : (P, 3) float
        The flexspline rim's ``dx, dy, rot`` at each plane (sections, then the balls').
    rigid : (P, 2) float
        The rigid gear's ``dx, dy`` there.
    cam : (2,) float
        The cam's motion against its support.
    """

    rim: np.ndarray
    rigid: np.ndarray
    cam: np.ndarray

    @classmethod
    def zero(cls, planes: int) -> Motion:
        return cls(np.zeros((planes, 3)), np.zeros((planes, 2)), np.zeros(2))

    @property
    def sections(self) -> np.ndarray:
        """The rim against the rigid gear at each section, ``(S, 3)``: what the tooth pairs feel."""
        rel = self.rim[:-1].copy()
        rel[:, :2] -= self.rigid[:-1]
        return rel

    @property
    def ball(self) -> np.ndarray:
        """The rim's ``dx, dy, rot`` at the ball plane (against the housing, where the cam's support stands)."""
        return self.rim[-1]

    @property
    def centre(self) -> np.ndarray:
        """The rim against the rigid gear at the ball plane (the generator's centre section), ``(3,)``."""
        out = self.rim[-1].copy()
        out[:2] -= self.rigid[-1]
        return out

    def vector(self) -> np.ndarray:
        return np.concatenate([self.rim.ravel(), self.rigid.ravel(), self.cam])

    @classmethod
    def from_vector(cls, x: np.ndarray, planes: int) -> Motion:
        n3, n2 = 3 * planes, 2 * planes
        return cls(x[:n3].reshape(planes, 3).copy(), x[n3 : n3 + n2].reshape(planes, 2).copy(), x[n3 + n2 :].copy())

    def mix(self, other: Motion, w: float) -> Motion:
        """``(1 - w) self + w other`` (an under-relaxed step)."""
        return Motion(
            (1 - w) * self.rim + w * other.rim,
            (1 - w) * self.rigid + w * other.rigid,
            (1 - w) * self.cam + w * other.cam,
        )


@dataclass(frozen=True)
class Supports:
    """The freedoms of the load model and what holds them (docs/models.md 4.2), lengths mm, forces N.

    Attributes
    ----------
    spatial : bool
    planes : (P,) float
        Axial position of each contact plane from the open end: the sections (``model.zs``), then the balls'.
    names : tuple of str
        The freedoms (:data:`FREEDOMS_SPATIAL` or :data:`FREEDOMS_PLANAR`).
    stiffness : (r,) float
        Each freedom's support: 0 free, inf held, else N/mm (translations; tilts as N/mm per mm of lever squared,
        i.e. N mm/rad).
    lever : (P,) float
        Distance of each plane from the diaphragm, mm (the flexspline's tilt moves it by tilt times this).
    seat : (P,) float
        Distance of each plane from the rigid gear's seat, mm.
    lateral : (P, P) float or None
        The cup wall's lateral compliance between planes, mm/N (spatial).
    twist : (P, P) float or None
        The cup's torsional compliance between planes, rad/(N mm) (spatial).
    cup_twist : float
        Planar: the cup's torsional compliance at the generator's centre plane, rad/(N mm), added to the wind-up.
    derived : dict
        How each default was obtained, for the record (stiffness values in the model's units).
    """

    spatial: bool
    planes: np.ndarray
    names: tuple
    stiffness: np.ndarray
    lever: np.ndarray
    seat: np.ndarray
    lateral: np.ndarray | None
    twist: np.ndarray | None
    cup_twist: float
    derived: dict = field(default_factory=dict)

    @property
    def ball_plane(self) -> int:
        return len(self.planes) - 1

    def columns(self, A3: np.ndarray, cam: np.ndarray, plane: np.ndarray, tooth: np.ndarray) -> np.ndarray:
        """``-d gap / d a`` of every contact for every freedom, ``(m, r)``.

        ``A3`` ``(m, 3)``: each contact's rim row; ``cam`` ``(m, 2)``: its cam row (a ball's normal, 0 for a tooth);
        ``plane`` ``(m,)`` its plane; ``tooth`` ``(m,)`` bool.
        """
        t = tooth.astype(float)[:, None]
        xy = A3[:, :2]
        cols = [A3[:, 2:3], xy]
        if self.spatial:
            cols.append(xy * self.lever[plane][:, None])
        cols.append(-xy * t)
        if self.spatial:
            cols.append(-xy * (t * self.seat[plane][:, None]))
        cols.append(cam)
        return np.concatenate(cols, axis=1)

    def field(self, A3: np.ndarray, plane: np.ndarray):
        """The cup's fields as ``(U, W)``: the contacts' compliance gains ``U W U'`` (``U`` ``(m, q)``, ``W``
        ``(q, q)``); None for the planar model."""
        if not self.spatial:
            return None
        P = len(self.planes)
        m = len(plane)
        U = np.zeros((m, 3 * P))
        r = np.arange(m)
        U[r, 2 * plane] = A3[:, 0]
        U[r, 2 * plane + 1] = A3[:, 1]
        U[r, 2 * P + plane] = A3[:, 2]
        W = np.zeros((3 * P, 3 * P))
        W[: 2 * P : 2, : 2 * P : 2] = self.lateral
        W[1 : 2 * P : 2, 1 : 2 * P : 2] = self.lateral
        W[2 * P :, 2 * P :] = self.twist
        return U, W

    def f_ext(self, torque_nmm: float) -> np.ndarray:
        """The external loads on the freedoms: the output torque on the flexspline's rotation, N mm."""
        f = np.zeros(len(self.names))
        f[0] = torque_nmm
        return f

    def plane_motion(self, a: np.ndarray, field_disp: np.ndarray | None) -> Motion:
        """The members' motion at every plane from the freedoms ``a`` and the cup's field displacements
        ``field_disp`` (``-W U' F`` of :meth:`field`, or None)."""
        P = len(self.planes)
        g = dict(zip(self.names, a))
        rim = np.zeros((P, 3))
        rigid = np.zeros((P, 2))
        rim[:, 0], rim[:, 1], rim[:, 2] = g["flex_x"], g["flex_y"], g["rot"]
        rigid[:, 0], rigid[:, 1] = g["rigid_x"], g["rigid_y"]
        if self.spatial:
            rim[:, 0] += g["flex_tilt_x"] * self.lever
            rim[:, 1] += g["flex_tilt_y"] * self.lever
            rigid[:, 0] += g["rigid_tilt_x"] * self.seat
            rigid[:, 1] += g["rigid_tilt_y"] * self.seat
            if field_disp is not None:
                rim[:, 0] += field_disp[0 : 2 * P : 2]
                rim[:, 1] += field_disp[1 : 2 * P : 2]
                rim[:, 2] += field_disp[2 * P :]
        return Motion(rim, rigid, np.array([g["cam_x"], g["cam_y"]]))

    def output_rotation(self, a: np.ndarray, torque_nmm: float) -> float:
        """The output's rotation against the rigid gear, rad: the diaphragm's (spatial), or the rim's plus the cup's
        twist in series (planar)."""
        return float(a[0]) + (0.0 if self.spatial else self.cup_twist * torque_nmm)


def build_supports(
    drive, zs: np.ndarray, E: float, G: float, t_cup: float, spec, spatial: bool | None = None, plate=None
):
    """The :class:`Supports` of a drive's load model from its ``[supports]`` table ``spec`` (docs/models.md 4.2).

    ``zs``: the sections' axial positions; ``E``, ``G`` the material's moduli (MPa); ``t_cup`` the cup wall;
    ``plate``: the diaphragm ``(r_i, r_o, h)`` (mm), default its ``[parts]`` sizes.
    """
    d = drive.design
    g = d.generator
    bw = d.drive.face_width
    spatial = (spec.rim == "spatial") if spatial is None else spatial
    z_h = g.generator_z if g.generator_z is not None else 0.5 * bw
    planes = np.concatenate([np.asarray(zs, dtype=float), [float(z_h)]])
    derived: dict = {}
    k_ob = spec.stiffness("output_bearing_radial_n_per_mm")
    k_obt = spec.stiffness("output_bearing_tilt_nm_per_rad")
    k_rr = spec.stiffness("rigid_gear_radial_n_per_mm")
    k_rt = spec.stiffness("rigid_gear_tilt_nm_per_rad")
    k_cam = spec.stiffness("cam_radial_n_per_mm")
    seat_z = 0.5 * bw if spec.rigid_gear_seat_mm is None else float(spec.rigid_gear_seat_mm)
    seat = planes - seat_z
    cup = g.cone_length is not None and not drive.external
    if cup:
        L_c = float(g.cone_length)
        lever = L_c - planes
        r_c = drive.flex_rim_radius + 0.5 * t_cup
        k_d = spec.stiffness("diaphragm_tilt_nm_per_rad")
        if k_d is None:
            r_i, r_o, h, given = diaphragm_geometry(drive, t_cup) if plate is None else (*plate, False)
            k_d = plate_tilt_stiffness(r_i, r_o, h, E, d.material.poisson)
            derived["diaphragm_tilt"] = {
                "model": "annular plate clamped at the cup's bolt circle, rigid joint to the wall",
                "r_i_mm": r_i,
                "r_o_mm": r_o,
                "h_mm": h,
                "from_parts": given,
                "stiffness_nmm_per_rad": k_d,
            }
        k_tilt = _series(k_d, k_obt)
        L_t = L_c - bw  # the plain wall: diaphragm to the toothed rim
        EI = E * pi * r_c**3 * t_cup
        kGA = _KAPPA_TUBE * G * 2.0 * pi * r_c * t_cup
        lateral = tube_lateral_compliance(lever, L_t, EI, kGA)
        h1 = d.flexspline.rim_thickness
        r_rim = drive.flex_rim_radius + 0.5 * h1 * (1.0 if drive.flex.r_f > drive.flex_rim_radius else -1.0)
        GJ_rim = G * 2.0 * pi * r_rim**3 * h1
        GJ_cup = G * 2.0 * pi * r_c**3 * t_cup
        twist = twist_compliance(planes, L_c, [(0.0, bw, GJ_rim), (bw, L_c, GJ_cup)])
        derived["cup"] = {"wall_mm": t_cup, "length_mm": L_t, "EI_nmm2": EI, "kGA_n": kGA, "GJ_nmm2": GJ_cup}
    else:
        # no cup (a ring flexspline, or no coning data): nothing ties the rim to the output but the torque; its
        # translation floats, and there is no plane-to-plane tilt or twist to model
        lever = np.zeros_like(planes)
        k_tilt = np.inf
        lateral = np.zeros((len(planes), len(planes)))
        twist = np.zeros((len(planes), len(planes)))
        k_ob = 0.0
        derived["cup"] = None
    ib = len(planes) - 1
    if spatial and cup:
        stiff = [0.0, k_ob, k_ob, k_tilt, k_tilt, k_rr, k_rr, k_rt, k_rt, k_cam, k_cam]
        names = FREEDOMS_SPATIAL
    else:
        spatial = False
        # the equivalent supports at the ball plane (the generator's centre section), where the planar rim lives
        c_flex = (1.0 / k_ob if k_ob > 0 else np.inf) + (lever[ib] ** 2 / k_tilt if k_tilt > 0 else np.inf)
        c_flex += lateral[ib, ib]
        c_rigid = (1.0 / k_rr if k_rr > 0 else np.inf) + (seat[ib] ** 2 / k_rt if k_rt > 0 else np.inf)
        k_f = 0.0 if np.isinf(c_flex) else (np.inf if c_flex == 0 else 1.0 / c_flex)
        k_r = 0.0 if np.isinf(c_rigid) else (np.inf if c_rigid == 0 else 1.0 / c_rigid)
        stiff = [0.0, k_f, k_f, k_r, k_r, k_cam, k_cam]
        names = FREEDOMS_PLANAR
        derived["planar_equivalent"] = {"flex_n_per_mm": k_f, "rigid_n_per_mm": k_r}
    return Supports(
        spatial,
        planes,
        names,
        np.array(stiff, dtype=float),
        lever,
        seat,
        lateral if spatial else None,
        twist if spatial else None,
        float(twist[ib, ib]),
        derived,
    )
