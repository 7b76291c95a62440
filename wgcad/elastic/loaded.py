"""The loaded flexspline as a deformation law: analytic cam law + elastic ring field + rigid-body motion (docs/models.md 3.1, 4.1)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from ..laws import Law, RimState
from .ring import Ring

__all__ = ["LoadedLaw", "displacements_many"]


@dataclass(frozen=True, slots=True)
class LoadedLaw(Law):
    """Neutral line of the loaded flexspline, usable wherever a :class:`~wgcad.laws.Law` is.

    ``state(phi)`` = ``scale`` times the ring's response to the contact loads
    (n >= 2 modes, :class:`Ring`; the rim is round when unloaded and the
    cam's balls are among the loads, so this is the whole deformation) + the
    rigid-body motion ``(dx, dy, rot)`` of the rim (first order in ``rot``:
    ``w -= rot v``, ``v += rot (r_m + w)``, ``theta += rot``, with the
    section's nominal law standing for the deformed rim in these second-order
    coupling terms). ``phi`` is the
    material angle from the generator's major axis as for every law; the
    loads are expressed in the generator frame, so the state is the one the
    drive holds at the generator angle it was solved for, and the clearance
    engine, the pictures and the kinematic-error model use it unchanged
    (quasi-static: teeth passing through keep this rim shape).

    Attributes
    ----------
    centre : Law
        Nominal law of the generator's centre section (amplitude ``w0_ref``).
    section : Law
        Nominal law of this section (coned amplitude ``w0``).
    ring : Ring
    psi : (L,) float
        Angles of the generalized loads, rad.
    loads : (L, 3) float
        Radial force, tangential force (N), couple (N mm) on the ring at ``psi``.
    scale : float
        Coning factor of the elastic field at this section, ``W0(z)/W0``.
    rigid : (3,) float
        ``dx, dy`` (mm, generator frame) and ``rot`` (rad, counter-clockwise) of the rim.
    phase : float
        The law is ``state(phi + phase)`` (``pi``: the second wave seen as the first).
    """

    name: ClassVar[str] = "loaded"
    linear_in_w0: ClassVar[bool] = False
    centre: Law
    section: Law
    ring: Ring
    psi: np.ndarray
    loads: np.ndarray
    scale: float = 1.0
    rigid: tuple = (0.0, 0.0, 0.0)
    phase: float = 0.0
    w0: float = field(init=False)
    r_m: float = field(init=False)
    n_waves: int = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "w0", float(self.section.w0))
        object.__setattr__(self, "r_m", float(self.section.r_m))
        object.__setattr__(self, "n_waves", int(self.section.n_waves))
        psi = np.array(self.psi, dtype=float)
        loads = np.array(self.loads, dtype=float).reshape(len(psi), 3)
        psi.flags.writeable = False
        loads.flags.writeable = False
        object.__setattr__(self, "psi", psi)
        object.__setattr__(self, "loads", loads)
        object.__setattr__(self, "rigid", tuple(float(x) for x in self.rigid))

    @property
    def tooth_offset(self) -> float:
        """The section's tooth offset (face modification, docs/models.md 13.4): loading moves the rim, not the teeth on it."""
        return self.section.tooth_offset

    def with_w0(self, w0: float) -> LoadedLaw:
        """The loaded law of the section whose nominal amplitude is ``w0`` (coning scales the elastic field alike)."""
        return replace(self, section=self.centre.with_w0(w0), scale=float(w0) / float(self.centre.w0))

    def shifted(self, phase: float) -> LoadedLaw:
        """This state seen from ``phase`` further on: ``state(phi) -> state(phi + phase)`` (e.g. ``pi`` for the other wave)."""
        return replace(self, phase=self.phase + float(phase))

    def elastic(self, phi) -> dict:
        """Elastic field alone at ``phi`` (dict of ``w, dw, d2w, v, dv, theta, dtheta``), this section's scale applied."""
        f = self.ring.field(np.ravel(phi), self.psi, self.loads)
        return {k: self.scale * v.reshape(np.shape(phi)) for k, v in f.items()}

    def _state(self, phi: np.ndarray) -> RimState:
        p = phi + self.phase
        return self._combine(phi, self.section.state(p), self.elastic(p))

    def _combine(self, phi, nom: RimState, el: dict) -> RimState:
        """The loaded state from the nominal one and the (scaled) elastic field at ``phi + phase``."""
        p = phi + self.phase
        dx, dy, rot = self.rigid
        c, s = np.cos(p), np.sin(p)
        w_t = dx * c + dy * s
        v_t = -dx * s + dy * c
        return RimState(
            phi,
            w=el["w"] + w_t - rot * nom.v,
            dw=el["dw"] + v_t - rot * nom.dv,
            d2w=el["d2w"] - w_t + rot * nom.dw,
            v=el["v"] + v_t + rot * (self.r_m + nom.w),
            dv=el["dv"] - w_t + rot * nom.dw,
            theta=el["theta"] + rot,
            dtheta=el["dtheta"],
        )


def _unique_eval(fn, arrays):
    """``[fn(a) for a in arrays]`` for a function of a 1-D array that acts pointwise: one call on the distinct arrays joined."""
    uniq: dict = {}
    for a in arrays:
        uniq.setdefault(a.tobytes(), a)
    keys = list(uniq)
    joined = np.concatenate([uniq[k] for k in keys])
    res = fn(joined)
    out, at = {}, 0
    for k in keys:
        n = uniq[k].size
        out[k] = tuple(r[at : at + n] for r in res)
        at += n
    return [out[a.tobytes()] for a in arrays]


def displacements_many(laws, phis) -> list[tuple]:
    """``w, v, theta`` of each law at its angles ``phis[k]`` (1-D), evaluated together.

    The sections and waves of a load state share their loads and the
    sections their angles, the levels of a sweep share the nominal section
    laws: each distinct ring field and nominal state is evaluated once, over
    all the angles that need it. The figures are those of ``law.state``.
    """
    out = [None] * len(laws)
    loaded = [k for k, law in enumerate(laws) if isinstance(law, LoadedLaw)]
    for k, law in enumerate(laws):
        if k not in loaded:
            st = law.state(phis[k])
            out[k] = (st.w, st.v, st.theta)
    ps = {k: np.asarray(phis[k], dtype=float).ravel() + laws[k].phase for k in loaded}
    el, nom = {}, {}
    groups: dict = {}
    for k in loaded:
        law = laws[k]
        groups.setdefault((id(law.ring), law.psi.tobytes(), law.loads.tobytes()), []).append(k)
    for ks in groups.values():
        law0 = laws[ks[0]]
        res = _unique_eval(lambda p: law0.ring.displacements(p, law0.psi, law0.loads), [ps[k] for k in ks])
        el.update(zip(ks, res))
    sec: dict = {}
    for k in loaded:
        sec.setdefault(id(laws[k].section), []).append(k)
    for ks in sec.values():
        section = laws[ks[0]].section

        def nominal(p, section=section):
            st = section.state(p)
            return st.w, st.v, st.theta

        nom.update(zip(ks, _unique_eval(nominal, [ps[k] for k in ks])))
    for k in loaded:
        law = laws[k]
        p = ps[k]
        (nw, nv, _), (ew, ev, eth) = nom[k], el[k]
        dx, dy, rot = law.rigid
        c, s = np.cos(p), np.sin(p)
        out[k] = (
            law.scale * ew + dx * c + dy * s - rot * nv,
            law.scale * ev - dx * s + dy * c + rot * (law.r_m + nw),
            law.scale * eth + rot,
        )
    return out
