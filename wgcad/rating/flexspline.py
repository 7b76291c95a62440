"""Stresses of the flexspline in one load state and their fatigue safety: rim at the tooth roots, tooth bending, cup wall (docs/models.md 10.1-10.3)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi, sqrt
from pathlib import Path

import numpy as np

from wgcad.design.parts import PartsSpec, load_parts

from .diaphragm import Diaphragm, diaphragm_stress
from .fatigue import Strength, goodman_safety
from .plate_sizing import plate_of, sized_parts
from .rim import RimCycle, curvature_change, torque_shear

__all__ = ["StressSetup", "stress_setup", "SectionStress", "state_stresses", "tooth_stress_factor"]

#: angles at which a section's cycle is sampled (the tooth angles are added to them)
CYCLE_SAMPLES = 1440


def tooth_stress_factor(s_f: float, h_f: float, rho_f: float) -> float:
    """ISO 6336-3's stress correction factor ``Y_S = (1.2 + 0.13 L) q_s^(1/(1.21 + 2.3/L))``, ``L = s_F/h_F``,
    ``q_s = s_F/(2 rho_F)`` held in the formula's range ``1 <= q_s < 8``."""
    L = s_f / max(h_f, 1e-9)
    qs = min(max(s_f / (2.0 * rho_f), 1.0), 7.99)
    return (1.2 + 0.13 * L) * qs ** (1.0 / (1.21 + 2.3 / L))


@dataclass(frozen=True, slots=True)
class StressSetup:
    """What the stresses of every state share: geometry, the root's concentration, the material (mm, MPa)."""

    E: float
    h1: float
    t_cup: float | None
    r_m: float
    r_cup: float
    y_root: float
    kt: float
    kf: float
    q: float
    rho_f: float
    s_f: float
    r_f: float
    strength: Strength
    nu: float = 0.3
    #: the cup's diaphragm (None without a cup) and its centre law's amplitude, mm
    plate: Diaphragm | None = None
    w0_centre: float = 0.0
    plate_z: float = 0.0
    #: whether the design's [parts] gives the diaphragm (thickness and bolt circle); rated either way (the part set
    #: sizes what [parts] leaves out, :mod:`wgcad.rating.plate_sizing`)
    plate_given: bool = False
    #: the part set's warnings on the diaphragm (sizes given, or the best admissible, below the criterion)
    plate_warnings: tuple = ()


def part_set_sizes(drive):
    """The part set's sizes of ``drive`` (:func:`wgcad.rating.plate_sizing.sized_parts`) from its file's ``[parts]``
    (the derived defaults when the design is in memory)."""
    d = drive.design
    spec = load_parts(d.source) if d.source and Path(d.source).is_file() else PartsSpec()
    return spec, sized_parts(spec, drive)


def _plate(drive) -> tuple[Diaphragm, bool, tuple]:
    """The diaphragm the part set exports (clamped at the cup's bolt circle, an assumption the datasheet states),
    whether the design file gives its sizes, and the part set's warnings on it."""
    spec, sizes = part_set_sizes(drive)
    given = spec.diaphragm_thickness is not None and spec.cup_bolt_circle_diameter is not None
    return plate_of(drive, sizes.values), given, tuple(n for n in sizes.notes if n.startswith("diaphragm"))


def stress_setup(drive, kt: float, strength: Strength) -> StressSetup:
    d = drive.design
    flex = drive.flex
    h1 = d.flexspline.rim_thickness
    rho_f = max(flex.spec.fillet_coef * d.drive.module, 1e-3)
    q = strength.notch_sensitivity(rho_f)
    t_cup = (d.material.cup_wall_thickness_mm or h1) if drive.coned else None
    outside = flex.r_f > drive.flex_rim_radius
    plate = _plate(drive) if t_cup is not None and outside else None
    return StressSetup(
        E=d.material.youngs_modulus_gpa * 1e3,
        h1=h1,
        t_cup=t_cup,
        r_m=drive.r_m,
        r_cup=drive.flex_rim_radius + 0.5 * (t_cup or h1) * (1 if not outside else -1),
        y_root=(0.5 if outside else -0.5) * h1,
        kt=kt,
        kf=1.0 + q * (kt - 1.0),
        q=q,
        rho_f=rho_f,
        s_f=float(flex.tooth_thickness(flex.r_f + rho_f)),
        r_f=flex.r_f,
        strength=strength,
        nu=d.material.poisson,
        plate=plate[0] if plate else None,
        w0_centre=drive.law.w0,
        plate_z=d.generator.cone_length if drive.coned else 0.0,
        plate_given=bool(plate and plate[1]),
        plate_warnings=plate[2] if plate else (),
    )


@dataclass(frozen=True, slots=True)
class SectionStress(RimCycle):
    """One place of the flexspline over a turn of the generator (MPa): its cycle (:class:`RimCycle`: ``psi``,
    ``sigma``, the surface stress at each angle from the major axis), and

    ``where``: ``root`` (toothed rim at the tooth roots, section ``z``) or
    ``cup`` (the cup wall where it leaves the toothed rim); the torque's
    ``shear``; Goodman's ``safety`` and the static ``yield_safety``.
    """

    where: str = "root"
    z: float = 0.0
    #: False: reported, but left out of the rating (its sizes are derived defaults, not the design's)
    rated: bool = True
    shear: float = 0.0
    safety: float = float("inf")
    yield_safety: float = float("inf")
    #: the largest nominal bending stress over the turn, MPa: the plain rim's ``E y dkappa`` without the root's
    #: concentration or the teeth's own bending (for a cosine law ``1.5 E h w0 / r^2``, docs/models.md 10.1)
    nominal: float = 0.0


def _tooth_bending(setup: StressSetup, state, section: int, law) -> tuple[np.ndarray, np.ndarray]:
    """Angles (rad) and root stresses (MPa) of the loaded teeth of a section: cantilever bending of the tooth by
    its whole contact force at the contact's height, times ISO 6336's ``Y_S``."""
    c = state.contacts
    sel = (c["kind"] == 1) & (c["section"] == section) & (c["force"] > 0)
    if not sel.any():
        return np.empty(0), np.empty(0)
    phi = c["phi"][sel]
    F = c["force"][sel]
    w = law.state(phi).w
    h_f = np.maximum(np.hypot(*c["point"][sel].T) - (setup.r_f + w), 1e-3)
    b = float(state.model.widths[section])
    y_s = np.array([tooth_stress_factor(setup.s_f, h, setup.rho_f) for h in h_f])
    return phi, y_s * 6.0 * F * h_f / (b * setup.s_f**2)


def _section(where, z, psi, sigma, shear, st: Strength, rated: bool = True, nominal=None) -> SectionStress:
    cyc = RimCycle(psi, sigma)
    vm = sqrt(float(np.abs(sigma).max()) ** 2 + 3.0 * shear**2)
    safety = goodman_safety(cyc.amplitude, cyc.mean, shear, st)
    nom = float(np.abs(sigma if nominal is None else nominal).max())
    return SectionStress(
        psi, sigma, where=where, z=z, rated=rated, shear=shear, safety=safety, yield_safety=st.yield_ / vm, nominal=nom
    )


def state_stresses(setup: StressSetup, state) -> list[SectionStress]:
    """The root of every section and the cup wall in ``state`` (a solved :class:`~wgcad.elastic.LoadState`)."""
    m = state.model
    base = np.linspace(0.0, 2 * pi, CYCLE_SAMPLES, endpoint=False)
    out = []
    tau_rim = torque_shear(state.torque_nm, setup.r_m, setup.h1)
    for i, law in enumerate(state.laws):
        phi_t, s_t = _tooth_bending(setup, state, i, law)
        psi = np.concatenate([base, np.mod(phi_t, 2 * pi)])
        plain = setup.E * setup.y_root * curvature_change(law, psi)
        sigma = setup.kf * plain
        sigma[len(base) :] += s_t
        order = np.argsort(psi, kind="stable")
        out.append(_section("root", float(m.zs[i]), psi[order], sigma[order], tau_rim, setup.strength, True, plain))
    if setup.t_cup is not None:
        law = state.laws[-1]  # the section at the rim's inner end, where the cup wall starts
        y = np.sign(setup.y_root) * 0.5 * setup.t_cup
        sigma = setup.E * y * curvature_change(law, base)
        tau = torque_shear(state.torque_nm, setup.r_cup, setup.t_cup)
        out.append(_section("cup", float(m.zs[-1]), base, sigma, tau, setup.strength))
    if setup.plate is not None:
        p = setup.plate
        psi, hub, wall = diaphragm_stress(state.laws[0].with_w0(setup.w0_centre), p, setup.E, setup.nu)
        for where, r, sigma in (("diaphragm_hub", p.r_i, hub), ("diaphragm_wall", p.r_o, wall)):
            tau = torque_shear(state.torque_nm, r, p.h)
            out.append(_section(where, setup.plate_z, psi, sigma, tau, setup.strength))
    return out
