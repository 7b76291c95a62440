"""Transitions between sectors under load: the loaded sectored drive at every knot of half a turn, the output's motion
law with the drive's compliance, the tooth forces, and how much they jump across the sector boundaries
(docs/models.md 2.3, 4.1).

The elastic model is posed at the knots of the motion law (:mod:`wgcad.sector.loaded`): half a turn holds every state
(identical waves). A *step* is the move from one knot to the next; what the load adds to the output over a step is
the change of the rim's rotation against the rigid gear (the kinematic law's own change is exact). A step lies *at a
boundary* when either of its knots is closer to a sector boundary than the mesh reaches (the largest angle from the
major axis of a loaded tooth over the cycle): the teeth of both sectors can then carry load; the others are
*interior* steps, where a sector meets the flexspline alone.
"""

from __future__ import annotations

import dataclasses
import time
from math import pi

import numpy as np

__all__ = ["LoadedCycle", "TransitionFigures", "loaded_cycle", "transition_figures"]


def _wrap(a):
    return (np.asarray(a) + pi) % (2.0 * pi) - pi


@dataclasses.dataclass(frozen=True)
class LoadedCycle:
    """The loaded sectored drive at every knot of half a turn (lengths mm, angles rad, forces N; arrays over the knots
    ``(K,)`` and rigid teeth ``(N,)``; :class:`~wgcad.sector.loaded.KnotState` says what each holds).

    ``phi_h`` is each state's generator angle (the knot plus the rim's rotation), ``deviation`` what the load adds to
    the output there: ``output_loaded - output_kinematic``.
    """

    torque_nm: float
    heights: np.ndarray
    knots: np.ndarray
    phi_h: np.ndarray
    output_kinematic: np.ndarray
    output_loaded: np.ndarray
    rim_rotation: np.ndarray
    residual_rotation: np.ndarray
    rigid_forces: np.ndarray
    flex_teeth: np.ndarray
    reach: np.ndarray
    check_mm: float
    solves: np.ndarray
    seconds: float

    @property
    def deviation(self) -> np.ndarray:
        """What the load adds to the output at each state, rad (the loaded output less the motion law's)."""
        return self.output_loaded - self.output_kinematic


def loaded_cycle(gear: dict, torque_nm: float, heights=None, model=None, progress=None) -> LoadedCycle:
    """Solve the sectored drive of ``gear`` (:func:`wgcad.sector.built.built_gear`) under ``torque_nm`` at every knot
    of half a turn (:func:`wgcad.sector.loaded.solve_knot`), each state warm-started from the previous
    (``heights`` overrides the built ones).

    ``model``: the drive's :class:`~wgcad.elastic.ElasticModel` if already built; ``progress(done, total)``.

    Raises
    ------
    DesignError
        The design lacks what the elastic model needs (``[material]``, ``[bearing]``), or no tooth contact can carry
        the torque.
    ContactSolveError
        A state did not converge.
    """
    from ..elastic import build_model
    from .loaded import solve_knot
    from .motion import motion_law

    t0 = time.perf_counter()
    drive, lay = gear["drive"], gear["layout"]
    h = np.asarray(gear["built"] if heights is None else heights, dtype=float)
    model = build_model(drive) if model is None else model
    law = motion_law(lay, drive.design.drive.z_flex)
    K = lay.n_teeth // drive.design.drive.waves  # the knots of one wave period (identical waves)
    states, prev = [], None
    for n, knot in enumerate(law.knots[:K]):
        prev = solve_knot(model, gear, h, law, float(knot), torque_nm, warm=prev)
        states.append(prev)
        if progress:
            progress(n + 1, K)

    def arr(name):
        return np.array([getattr(s, name) for s in states])

    return LoadedCycle(
        torque_nm=float(torque_nm),
        heights=h,
        knots=arr("knot"),
        phi_h=arr("generator_angle"),
        output_kinematic=arr("output_kinematic"),
        output_loaded=arr("output_loaded"),
        rim_rotation=arr("rim_rotation"),
        residual_rotation=arr("residual_rotation"),
        rigid_forces=np.stack([s.rigid_forces for s in states]),
        flex_teeth=arr("flex_teeth"),
        reach=arr("reach"),
        check_mm=float(max(s.check_mm for s in states)),
        solves=arr("solves"),
        seconds=time.perf_counter() - t0,
    )


@dataclasses.dataclass(frozen=True)
class TransitionFigures:
    """How the loaded drive changes from knot to knot, at the boundaries and inside the sectors (rad, N).

    ``*_boundary`` is the largest over the steps at a boundary, ``*_interior`` over the interior steps (module
    docstring), ``*_at`` the generator angle of the step's first knot. ``output_jump``: the change of the load's
    part of the output over a step (:attr:`LoadedCycle.deviation`); ``peak_force_jump``: the change of the largest
    tooth force; ``tooth_force_jump``: the largest change of one rigid tooth's force. ``lowered_force``: the largest
    force a lowered tooth carries, on ``lowered_tooth`` at ``lowered_at`` (0, -1, NaN: none is lowered or loaded).
    """

    reach: float
    boundaries: np.ndarray
    steps_boundary: int
    steps_interior: int
    output_jump_boundary: float
    output_jump_boundary_at: float
    output_jump_interior: float
    peak_force_jump_boundary: float
    peak_force_jump_boundary_at: float
    peak_force_jump_interior: float
    tooth_force_jump_boundary: float
    tooth_force_jump_interior: float
    peak_force_boundary: float
    peak_force_interior: float
    lowered_force: float
    lowered_tooth: int
    lowered_at: float
    output_range: float


def _largest(x: np.ndarray, sel: np.ndarray, at: np.ndarray) -> tuple[float, float]:
    if not sel.any():
        return 0.0, float("nan")
    i = np.nonzero(sel)[0][np.argmax(np.abs(x[sel]))]
    return float(x[i]), float(at[i])


def transition_figures(cycle: LoadedCycle, layout, full_height: float) -> TransitionFigures:
    """The figures of :class:`TransitionFigures` for ``cycle`` on the sectored gear ``layout``."""
    ph = cycle.phi_h
    K = len(ph)
    period = 2.0 * pi * K / layout.n_teeth  # the half turn (identical waves)
    nxt = np.append(ph[1:], ph[0] + period)
    # the state after the last knot is the first one a wave later: the steps close the period
    rim = np.append(cycle.deviation, cycle.deviation[0])
    F = np.vstack([cycle.rigid_forces, cycle.rigid_forces[:1]])
    # a wave later every rigid tooth's force is its partner's a wave ahead: tooth i -> i + N / waves
    F[-1] = np.roll(cycle.rigid_forces[0], K)
    d_rim = np.diff(rim)
    peak = F.max(axis=1)
    d_peak = np.diff(peak)
    d_tooth = np.abs(np.diff(F, axis=0)).max(axis=1)
    reach = float(cycle.reach.max())
    b = np.asarray(layout.bounds[:-1], dtype=float)

    def near(a):
        return np.abs(_wrap(np.asarray(a)[:, None] - b[None, :])).min(axis=1) < reach

    at_b = near(ph) | near(nxt)
    inner = ~at_b
    ob, ob_at = _largest(d_rim, at_b, ph)
    oi, _ = _largest(d_rim, inner, ph)
    pb, pb_at = _largest(d_peak, at_b, ph)
    pi_, _ = _largest(d_peak, inner, ph)
    low = np.asarray(cycle.heights) < full_height - 1e-9
    lf = cycle.rigid_forces[:, low] if low.any() else np.zeros((K, 0))
    if lf.size and lf.max() > 0:
        k, j = np.unravel_index(np.argmax(lf), lf.shape)
        lowered = (float(lf[k, j]), int(np.nonzero(low)[0][j]), float(ph[k]))
    else:
        lowered = (0.0, -1, float("nan"))
    peak_k = cycle.rigid_forces.max(axis=1)
    at_k = near(ph)
    return TransitionFigures(
        reach=reach,
        boundaries=b,
        steps_boundary=int(at_b.sum()),
        steps_interior=int(inner.sum()),
        output_jump_boundary=ob,
        output_jump_boundary_at=ob_at,
        output_jump_interior=oi,
        peak_force_jump_boundary=pb,
        peak_force_jump_boundary_at=pb_at,
        peak_force_jump_interior=pi_,
        tooth_force_jump_boundary=float(d_tooth[at_b].max()) if at_b.any() else 0.0,
        tooth_force_jump_interior=float(d_tooth[inner].max()) if inner.any() else 0.0,
        peak_force_boundary=float(peak_k[at_k].max()) if at_k.any() else 0.0,
        peak_force_interior=float(peak_k[~at_k].max()) if (~at_k).any() else 0.0,
        lowered_force=lowered[0],
        lowered_tooth=lowered[1],
        lowered_at=lowered[2],
        output_range=float(np.ptp(cycle.deviation)),
    )
