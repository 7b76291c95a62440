"""Tooth poses of an imperfect drive: run-out, eccentricity and cam mounting error on every tooth (docs/models.md 6.2).

The poses have the form of :func:`wgcad.placement.tooth_pose` (a rotation
and a shift per tooth, rigid-gear frame), so the clearance primitives, the
pictures and the exports can take an imperfect drive without knowing where
a pose came from. How each error moves a tooth (first harmonic of each,
docs/models.md 6.1, 6.2):

* run-out ``F`` of a gear, phase ``xi``: tooth i, at angle ``a_i`` in its
  own gear, sits ``(F / 2) sin(a_i + xi)`` further along the pitch circle
  (an angular deviation ``F / (2 r)``); the flexspline's tooth moves along
  its deformed rim (it takes the rim's state at its displaced angle);
* geometric eccentricity ``e`` of a gear, phase ``psi``: the pitch circle's
  centre is off by ``e`` towards ``psi``. The rigid gear translates. A
  flexspline tooth rides its rim ``e cos(a_i - psi)`` higher and
  ``e sin(psi - a_i)`` further along it (the translation of the undeformed
  ring, taken into the tooth's own frame);
* cam mounting error: the deformed rim and its teeth translate by
  ``e_h^h`` (turning with the cam), ``e_h^g`` (with the flexspline) and
  ``e_h^b`` (stationary); with coning each section by ``W0(z) / W0``,
  since the cup pivots at its diaphragm as it does for the deformation
  (docs/models.md 3.1);
* installation angles turn a gear's error pattern (run-out and
  eccentricity) about the axis; the teeth stay where a perfect gear's are
  (an installation turns a gear by whole pitches, < 1 deg off any angle).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from fractions import Fraction
from math import pi, radians

import numpy as np

from ..kinematics import gear_ratios
from .law import pose_from_displacements, tooth_pose

__all__ = [
    "Imperfections",
    "shortcuts",
    "full_cycle_turns",
    "flex_deviations",
    "rigid_deviations",
    "rigid_translation",
    "cam_offset",
    "coning_factor",
    "flex_poses",
    "flex_poses_batch",
    "rigid_poses",
]


#: the ``[imperfections]`` key (um or deg, by its suffix) of each :class:`Imperfections` attribute (mm or rad)
SPEC_KEYS = {
    "flex_runout": "flex_runout_um",
    "flex_runout_phase": "flex_runout_phase_deg",
    "rigid_runout": "rigid_runout_um",
    "rigid_runout_phase": "rigid_runout_phase_deg",
    "flex_ecc": "flex_eccentricity_um",
    "flex_ecc_phase": "flex_eccentricity_phase_deg",
    "rigid_ecc": "rigid_eccentricity_um",
    "rigid_ecc_phase": "rigid_eccentricity_phase_deg",
    "cam_cam": "cam_offset_cam_um",
    "cam_cam_phase": "cam_offset_cam_phase_deg",
    "cam_flex": "cam_offset_flex_um",
    "cam_flex_phase": "cam_offset_flex_phase_deg",
    "cam_fixed": "cam_offset_fixed_um",
    "cam_fixed_phase": "cam_offset_fixed_phase_deg",
    "rigid_install": "rigid_install_angle_deg",
    "flex_install": "flex_install_angle_deg",
}


@dataclass(frozen=True, slots=True)
class Imperfections:
    """The errors of :class:`~wgcad.design.imperfections.ImperfectionsSpec` in mm and rad.

    Attributes
    ----------
    flex_runout, rigid_runout : float
        F_g, F_b: peak-to-peak tooth-position error along the pitch circle, mm.
    flex_ecc, rigid_ecc : float
        Geometric eccentricities, mm.
    cam_cam, cam_flex, cam_fixed : float
        Cam mounting error components e_h^h, e_h^g, e_h^b, mm.
    *_phase : float
        Their phases, rad.
    rigid_install, flex_install : float
        Installation angles of the gears' error patterns, rad.
    """

    flex_runout: float = 0.0
    flex_runout_phase: float = 0.0
    rigid_runout: float = 0.0
    rigid_runout_phase: float = 0.0
    flex_ecc: float = 0.0
    flex_ecc_phase: float = 0.0
    rigid_ecc: float = 0.0
    rigid_ecc_phase: float = 0.0
    cam_cam: float = 0.0
    cam_cam_phase: float = 0.0
    cam_flex: float = 0.0
    cam_flex_phase: float = 0.0
    cam_fixed: float = 0.0
    cam_fixed_phase: float = 0.0
    rigid_install: float = 0.0
    flex_install: float = 0.0

    @classmethod
    def from_spec(cls, spec) -> Imperfections:
        """From the design table (um, deg) to mm, rad: each attribute from its named key (:data:`SPEC_KEYS`)."""
        return cls(
            **{
                attr: (1e-3 * getattr(spec, key) if key.endswith("_um") else radians(getattr(spec, key)))
                for attr, key in SPEC_KEYS.items()
            }
        )

    def replace(self, **changes) -> Imperfections:
        return dataclasses.replace(self, **changes)

    @property
    def gear_errors(self) -> bool:
        return any(v != 0.0 for v in (self.flex_runout, self.rigid_runout, self.flex_ecc, self.rigid_ecc))

    @property
    def amplitude(self) -> float:
        """The largest displacement of a tooth relative to its rigid tooth the errors allow, mm: every first-harmonic
        term at its full amplitude (half a run-out, twice the flexspline's eccentricity: its gear and its cam)."""
        return (
            0.5 * self.flex_runout
            + 2 * abs(self.flex_ecc)
            + abs(self.cam_cam)
            + abs(self.cam_flex)
            + abs(self.cam_fixed)
            + abs(self.rigid_ecc)
            + 0.5 * self.rigid_runout
        )


def shortcuts(imp: Imperfections) -> dict:
    """Which work-skipping facts of docs/models.md 7 still hold with these errors, and why.

    * mesh period: the scene in the generator frame repeats after a rigid
      pitch of generator rotation only if nothing is tied to a gear or the
      housing: it survives the cam-borne offset ``e_h^h`` alone (constant in
      the generator frame) and nothing else;
    * identical waves and mirror symmetry: any first-harmonic error treats
      the two zones differently; the mirror also survives a cam-borne offset
      along the major axis (phase 0 or 180 deg) when nothing else is set;
    * identical sections (no coning): unaffected, the errors are the same
      in every section (the cam offset scales with coning like W0).
    """
    others = imp.gear_errors or imp.cam_flex != 0.0 or imp.cam_fixed != 0.0
    flex_borne = imp.flex_runout != 0.0 or imp.flex_ecc != 0.0 or imp.cam_flex != 0.0
    cam_only = not others and imp.cam_cam != 0.0
    on_axis = cam_only and abs(np.sin(imp.cam_cam_phase)) < 1e-12
    perfect = not others and imp.cam_cam == 0.0
    return {
        "mesh_period": bool(not others),
        "identical_waves": bool(perfect),
        "mirror_symmetry": bool(perfect or on_axis),
        # errors tied to the flexspline meet those tied to the housing and the cam in a new phase every
        # generator turn (the flexspline turns by 1/u_hg): the cycle is then the whole of full_cycle_turns;
        # without them a generator turn later every tooth meets what its neighbour met (the perfect
        # teeth are alike), so one turn holds every state
        "one_generator_turn": bool(not flex_borne),
        "why": (
            "no errors"
            if perfect
            else "only the cam-borne offset: constant in the generator frame"
            if cam_only
            else "gear run-out/eccentricity or a flexspline-borne/stationary cam offset: the full cycle is needed"
        ),
    }


def full_cycle_turns(z_flex: int, z_rigid: int) -> int:
    """Generator turns after which an imperfect drive's state repeats: the numerator of ``|u_hg|`` in lowest terms.

    Every error is tied to the cam (a function of the generator angle mod
    2 pi), the housing or the flexspline (of its angle mod 2 pi); both come
    back together after ``p`` generator turns when ``|u_hg| = p / q``
    (``q`` flexspline turns): 100 for 200/202 teeth.
    """
    return Fraction(abs(z_flex), abs(z_rigid - z_flex)).numerator


def flex_deviations(imp: Imperfections, k, z_flex: int, r_flex: float):
    """Along-rim angular deviation (rad) and radial offset (mm) of flexspline teeth ``k``.

    Returns
    -------
    dalpha, drho : (K,) float
    """
    a = 2.0 * pi * np.asarray(k, dtype=float) / z_flex
    g = imp.flex_install
    dalpha = (0.5 * imp.flex_runout / r_flex) * np.sin(a - g + imp.flex_runout_phase)
    dalpha += (imp.flex_ecc / r_flex) * np.sin(imp.flex_ecc_phase + g - a)
    drho = imp.flex_ecc * np.cos(a - imp.flex_ecc_phase - g)
    return dalpha, drho


def rigid_deviations(imp: Imperfections, j, z_rigid: int, r_rigid: float):
    """Angular deviation (rad, about the axis) of rigid teeth ``j`` (tooth j centred at ``(j + 1/2) 2 pi / z_b``)."""
    a = (np.asarray(j, dtype=float) + 0.5) * 2.0 * pi / z_rigid
    return (0.5 * imp.rigid_runout / r_rigid) * np.sin(a - imp.rigid_install + imp.rigid_runout_phase)


def rigid_translation(imp: Imperfections) -> np.ndarray:
    """Translation of the whole rigid gear by its eccentricity, mm, ``(2,)``."""
    p = imp.rigid_ecc_phase + imp.rigid_install
    return imp.rigid_ecc * np.array([np.cos(p), np.sin(p)])


def cam_offset(imp: Imperfections, phi_h, phi_g, parts=("cam", "flex", "fixed")) -> np.ndarray:
    """Cam mounting error in the rigid-gear frame, mm, ``(..., 2)`` (docs/models.md 6.2).

    The cam-borne component points at ``f^h + phi_h``, the flexspline-borne
    one at ``f^g + phi_g``, the stationary one at ``f^b``; in the cam's axes
    these are the projections of docs/models.md 6.2.
    """
    phi_h = np.asarray(phi_h, dtype=float)
    phi_g = np.asarray(phi_g, dtype=float)
    x = np.zeros(np.broadcast(phi_h, phi_g).shape)
    y = np.zeros_like(x)
    for name, amp, ang in (
        ("cam", imp.cam_cam, imp.cam_cam_phase + phi_h),
        ("flex", imp.cam_flex, imp.cam_flex_phase + phi_g),
        ("fixed", imp.cam_fixed, imp.cam_fixed_phase + 0.0 * phi_h),
    ):
        if name in parts and amp != 0.0:
            x = x + amp * np.cos(ang)
            y = y + amp * np.sin(ang)
    return np.stack([x, y], axis=-1)


def coning_factor(drive, z) -> float:
    """``W0(z) / W0``: how a section's deformation (and cam offset) scales with coning; 1 without."""
    if z is None or not drive.coned:
        return 1.0
    return float(drive.law_at(z).w0 / drive.law.w0)


def flex_poses(drive, imp: Imperfections, phi_h: float, teeth=None, z=None):
    """Exact poses of flexspline teeth of an imperfect drive at generator angle ``phi_h``, rigid-gear frame.

    Parameters
    ----------
    drive : wgcad.drive.Drive
    imp : Imperfections
    phi_h : float
        Generator angle relative to the rigid gear, rad.
    teeth : (K,) int, optional
        Tooth indices (default all).
    z : float, optional
        Axial section, mm from the open end (default the generator's centre section).

    Returns
    -------
    rot : (K,) float
    shift : (K, 2) float
        ``R(rot) p + shift`` places the tooth outline ``p`` (tooth frame).
    """
    d = drive.design.drive
    z_g, z_b = d.z_flex, d.z_rigid
    k = np.arange(z_g) if teeth is None else np.asarray(teeth)
    phi_g = phi_h / gear_ratios(z_g, z_b)["u_hg"]
    dalpha, drho = flex_deviations(imp, k, z_g, drive.flex.r)
    phi = 2.0 * pi * k / z_g + phi_g + dalpha - phi_h
    law = drive.law if z is None else drive.law_at(z)
    rot, shift = tooth_pose(law, phi, drive.r_m, frame_angle=phi_h)
    shift = shift + drho[:, None] * np.stack([np.cos(rot), np.sin(rot)], axis=-1)
    shift = shift + coning_factor(drive, z) * cam_offset(imp, phi_h, phi_g)
    return rot, shift


def rigid_poses(drive, imp: Imperfections, teeth=None):
    """Exact poses of rigid teeth ``j`` (the tooth template centred on +x, turned to ``(j + 1/2) 2 pi / z_b``), rigid frame."""
    z_b = drive.design.drive.z_rigid
    j = np.arange(z_b) if teeth is None else np.asarray(teeth)
    rot = (j + 0.5) * 2.0 * pi / z_b + rigid_deviations(imp, j, z_b, drive.rigid.r)
    shift = np.broadcast_to(rigid_translation(imp), (len(rot), 2)).copy()
    return rot, shift


def flex_poses_batch(drive, imp: Imperfections, phi_h: np.ndarray, k: np.ndarray, sections: list):
    """Poses of flexspline teeth ``k`` at generator angles ``phi_h`` in every section, as :func:`wgcad.placement.imperfect.flex_poses`.

    Parameters
    ----------
    phi_h, k : (K,) float, int
        Generator angle (rad, relative to the rigid gear) and tooth of each sample.
    sections : list of (float or None)

    Returns
    -------
    list over sections of ``(rot (K,), shift (K, 2))``.

    For laws linear in W0 the law is evaluated once for every section
    (a coned section's displacements are the centre's scaled by ``W0(z)/W0``).
    """
    d = drive.design.drive
    z_g = d.z_flex
    phi_h = np.asarray(phi_h, dtype=float)
    k = np.asarray(k)
    phi_g = phi_h / gear_ratios(z_g, d.z_rigid)["u_hg"]
    dalpha, drho = flex_deviations(imp, k, z_g, drive.flex.r)
    phi = 2.0 * pi * k / z_g + phi_g + dalpha - phi_h
    E = cam_offset(imp, phi_h, phi_g)
    base = drive.law
    shared = base.linear_in_w0 and all(z is None or drive.coned for z in sections)
    st = base.state(phi) if shared else None
    out = []
    for z in sections:
        if shared:
            law = base if z is None else drive.law_at(z)
            f = law.w0 / base.w0
            rot, shift = pose_from_displacements(
                phi, f * st.w, f * st.v, f * st.theta, drive.r_m, phi_h, law.tooth_offset
            )
        else:
            law = base if z is None else drive.law_at(z)
            s2 = law.state(phi)
            rot, shift = pose_from_displacements(phi, s2.w, s2.v, s2.theta, drive.r_m, phi_h, law.tooth_offset)
        shift = shift + drho[:, None] * np.stack([np.cos(rot), np.sin(rot)], axis=-1)
        shift += coning_factor(drive, z) * E
        out.append((rot, shift))
    return out
