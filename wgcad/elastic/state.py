"""One load state of the drive: contact problem re-linearised on the exact tooth geometry until the teeth stop moving (docs/models.md 4, 4.1)."""

from __future__ import annotations

import time
from dataclasses import field, replace
from typing import NamedTuple

import numpy as np

from wgcad.errors import DesignError

from ..records import record
from .anderson import Anderson
from .cam import ball_rows, cam_excess, generator_torque, mounted
from .loaded import LoadedLaw
from .model import ElasticModel
from .pairs import GAP_MARGIN, MeasuredPairs
from .rim import (
    RADIAL_MARGIN,
    dense_loads,
    loads_on_table,
    merge_loads,
    tooth_origins,
    tooth_poses,
)
from .solve import ContactSolveError, solve_supported
from .tables import Compliance

__all__ = ["LoadState", "solve_load", "POSITION_TOL", "RADIAL_MARGIN", "GAP_MARGIN"]

#: Re-linearisation stops when no tooth moves by more than this between two
#: solutions, mm (0.2 um: a fifth of the 1 um chord tolerance of the outlines.
#: The gaps are exact for the polygons, whose contact points move from edge to
#: edge: below ~0.1 um the iteration sees that discreteness, not the drive).
POSITION_TOL = 2e-4
#: Contact forces below this are floored when the Hertz secants are taken, N
#: (the approach error it leaves is below 1e-5 mm for the balls and teeth of D1).
FORCE_FLOOR = 1e-2
_MAX_LINEARISATIONS = 100
#: Smallest relaxation of a cycling re-linearisation: its steps shrink to this share of the plain step.
_OMEGA_MIN = 1.0 / 64.0
#: Solutions the re-linearisation's Anderson acceleration combines (0: plain fixed-point iteration).
ANDERSON_DEPTH = 3
#: Every state's first pass solves the contact problem up to this many times, the Hertz contacts linearised
#: again about each solution's forces (no engine call: the poses have not moved). Linearised about a much
#: smaller load the balls (P ~ delta^(3/2)) are far too soft: one solve moved the teeth three times too far
#: (D1, 1500 N m from cold: 0.52 mm, then 0.37 mm back), and a warm start from 0 to 3000 N m crawled under
#: relaxation past 100 passes.
_HERTZ_START = 8
#: ... until the forces change by less than this share of the largest (a starting point, not the answer:
#: the passes that follow converge to the same fixed point).
_HERTZ_TOL = 0.1
_TRACE = None  # a list to record (pass, change, relaxation, pairs, loaded contacts) while debugging


@record(frozen=True)
class LoadState:
    """A solved load state (lengths mm, angles rad, forces N inside).

    Attributes
    ----------
    torque_nm : float
    cam_offset : (2,) float
        Cam axis offset ``e_h`` in the generator frame, mm.
    laws : list of LoadedLaw
        The loaded neutral line of each section (``model.zs``).
    rigid : (3,) float
        Rim translation ``dx, dy`` (mm) and rotation (rad, counter-clockwise) relative to the rigid gear.
    contacts : dict of arrays
        ``kind`` (0 ball, 1 tooth), ``section``, ``tooth``, ``flank`` (0 lower, 1 upper, -1 ball),
        ``phi`` (rad), ``force`` (N), ``gap`` (geometric gap at the solution, mm: exact, from the
        clearance engine, for every pair that carries load or could hold the smallest clearance, ``gap_exact``;
        the others are open wider and report their linearised gap),
        ``approach`` (contact compliance's share, mm), ``point`` (K, 2).
    residuals : dict
        ``equilibrium`` (relative), ``complementarity`` (relative), ``linearisation_mm``
        (exact minus linearised gap of the loaded contacts), ``iterations``, ``pivots``, ``position_change_mm``.
    timing : dict
        Seconds in ``geometry`` (exact engine, poses) and ``solver`` (compliance matrix, QP).
    """

    model: ElasticModel
    torque_nm: float
    cam_offset: np.ndarray
    laws: list
    rigid: np.ndarray
    contacts: dict
    residuals: dict
    timing: dict = field(default_factory=dict)
    #: the tooth pairs measured on the exact geometry at this state (a warm start's first pass reuses them)
    pairs: object = field(default=None, repr=False, compare=False)
    #: torque the balls put on the cam, N mm (counter-clockwise positive; frictionless: on average over a mesh
    #: period the output torque over the ratio, docs/models.md 4.1)
    generator_torque: float = 0.0
    #: the cam's motion against its support, mm (generator frame; zero when it is held)
    cam_shift: np.ndarray = field(default_factory=lambda: np.zeros(2))

    @property
    def mesh_wind_up(self) -> float:
        """Rotation of the toothed rim against the rigid gear, rad (signed so that it grows with torque)."""
        return float(self.model.torque_sign * self.rigid[2])

    @property
    def wind_up(self) -> float:
        """Output wind-up: rim rotation plus the cup's twist ``M / K_cup``, rad."""
        return self.mesh_wind_up + 1e3 * self.torque_nm / self.model.cup_stiffness

    def law(self, section: int = 0) -> LoadedLaw:
        return self.laws[section]


def _cam_offset(e_um: float, e_deg: float) -> np.ndarray:
    e = 1e-3 * e_um
    a = np.deg2rad(e_deg)
    return np.array([e * np.cos(a), e * np.sin(a)])


def _geometry(model: ElasticModel, loads: np.ndarray, rigid):
    """Every tooth pair within GAP_MARGIN measured on the exact geometry at the state ``(loads, rigid)``: keys, gaps, pairs."""
    rot, shift, origin, el, cand = tooth_poses(model, loads, rigid)
    pairs = MeasuredPairs(model)
    keys = pairs.update(rot, shift, origin, el, cand, rigid, full=True) if cand.size else np.zeros(0, dtype=int)
    return keys, pairs.gap[keys], pairs


def _assemble(model: ElasticModel, pairs: MeasuredPairs, keys, el, rigid, e, F_prev_ball, F_prev_teeth):
    """Vectors of the linearised contact problem (balls first, then the tooth pairs ``keys``): angle index, b, f, A, q, s."""
    br = model.bearing
    tab = model.tables
    Z = len(br.psi)
    # balls: along the cam's normals, the rim round when unloaded (cam.ball_rows, docs/models.md 4.1)
    rows = ball_rows(model, cam_excess(model), e)
    idx_b = tab.z_g + np.arange(Z)
    b_b, A_b = rows.b, rows.A
    o_b, s_b = br.tangent(F_prev_ball, FORCE_FLOOR)
    q_b = rows.q + o_b
    if len(keys) == 0:
        return idx_b, b_b, np.ones(Z), A_b, q_b, s_b
    sec, tooth = np.divmod(keys // 2, tab.z_g)
    f_t = model.scales[sec]
    width = model.widths[sec]
    o_t, s_t = model.teeth.tangent(F_prev_teeth, width, FORCE_FLOOR)
    s_t = s_t + model.teeth.bending(pairs.point[keys], pairs.normal[keys], width)
    q_t = pairs.q_geo[keys] + o_t
    return (
        np.concatenate([idx_b, tooth]),
        np.concatenate([b_b, pairs.b[keys]]),
        np.concatenate([np.ones(Z), f_t]),
        np.concatenate([A_b, np.pad(pairs.A[keys], ((0, 0), (0, 2)))]),
        np.concatenate([q_b, q_t]),
        np.concatenate([s_b, s_t]),
    )


def _first_guess(model: ElasticModel, keys, q, Z: int, torque_nm: float):
    """Contacts guessed to carry load in a state's first contact solve (cold, or warm from another torque): the
    closed ones (q < 0), less the non-working flanks under torque (the torque unloads them). Only the solver's
    starting point: its solution is unique (strictly convex), the pivots to reach it fewer."""
    act = q < 0.0
    if torque_nm > 0 and len(keys):
        working = 1 if model.scene.working == "upper" else 0
        act[Z:] &= (keys % 2) == working
    return act


def solve_load(
    model: ElasticModel,
    torque_nm: float,
    cam_offset_um: float = 0.0,
    cam_offset_deg: float = 0.0,
    tol: float = POSITION_TOL,
    warm: LoadState | None = None,
    tooth_errors=None,
) -> LoadState:
    """Solve the drive under output torque ``torque_nm`` with the cam axis offset by ``cam_offset_um`` at ``cam_offset_deg``.

    Generator at angle 0 (major axis on +x, tooth 0 on it, rigid gear fixed).
    Each pass: exact contact geometry of every tooth near engagement from the
    clearance engine at the current loaded poses; the linearised problem
    ``gap = q + (D + diag(s)) F - A a >= 0, F >= 0, F gap = 0, A'F = (0, 0, M)``
    with ``D`` the ring compliance, ``s`` the ball and tooth secant
    compliances, ``A`` the rim's rigid-body freedoms (docs/models.md 4.1);
    then the poses are updated and the pass repeated until no tooth moves by
    more than ``tol`` (mm).

    Raises
    ------
    DesignError
        Negative torque or offset; teeth that never meet while a torque is asked;
        a bearing that cannot carry the load.
    ContactSolveError
        No convergence (never a silent return).

    ``tooth_errors`` places the flexspline teeth of an imperfect drive
    relative to the rigid teeth: ``(turn, move)`` per tooth of every section
    (flattened ``section * z_g + tooth``), rad and mm
    (:mod:`wgcad.accuracy.ke_load` builds them from the run-out and
    eccentricities); the cam offset stays the physical input above.
    """
    _check_load_inputs(torque_nm, cam_offset_um, tol)
    e = _cam_offset(cam_offset_um, cam_offset_deg)
    f_ext = np.array([0.0, 0.0, model.torque_sign * 1e3 * torque_nm, 0.0, 0.0])
    Z = len(model.bearing.psi)
    n_keys = len(model.zs) * model.tables.z_g * 2
    loads, rigid, F_ball, pairs = _start(model, e, warm)
    state = _Iterate(
        loads, rigid, F_ball, np.zeros(n_keys), np.zeros(n_keys, dtype=bool), Anderson(model.drive.r_m, ANDERSON_DEPTH)
    )
    times = {"geometry": 0.0, "solver": 0.0}
    pivots = 0
    change = 0.0
    for it in range(_MAX_LINEARISATIONS):
        lin = _linearise(
            model,
            torque_nm,
            e,
            f_ext,
            pairs,
            state.loads,
            state.rigid,
            state.F_ball,
            state.F_teeth,
            state.active,
            it,
            tooth_errors,
        )
        keys, F, sol = lin.keys, lin.F, lin.sol
        pivots += lin.pivots
        times["geometry"] += lin.t_geo
        times["solver"] += lin.t_sol
        last = (keys, F, sol, lin.idx, lin.b, lin.f, pairs.point[keys], pairs.normal[keys], lin.cam_shift)
        loads_new = dense_loads(len(model.tables.angles), lin.idx, F, lin.f, lin.b)
        F_t_new = np.zeros(n_keys)
        F_t_new[keys] = F[Z:]
        # convergence: the largest move of an engaging tooth from the linearisation's poses to the solution's
        # (the fixed-point residual itself, from the tables: no engine call)
        o_new = tooth_origins(model, loads_new, sol.a, tooth_errors)
        k2 = keys // 2
        d = np.hypot(*(o_new[k2] - lin.origin[k2]).T)
        change = max(float(d.max()) if d.size else 0.0, abs(float(sol.a[2] - state.rigid[2])) * model.drive.r_m)
        if _TRACE is not None:
            _TRACE.append((it, change, state.omega, len(keys), int((F > 0).sum())))
        if change < tol:
            break
        if state.settled_after(change, tol):
            break
        active = np.zeros(n_keys, dtype=bool)
        active[keys] = F[Z:] > 0
        state.advance(it, change, tol, _Plain(loads_new, sol.a, F[:Z], F_t_new, active))
    else:
        raise ContactSolveError(
            f"the elastic model did not converge at {torque_nm:g} N m: tooth positions still moving by "
            f"{1e3 * change:.3g} um after {_MAX_LINEARISATIONS} re-linearisations; a looser tolerance, "
            "a nearby torque or more side clearance may let it settle"
        )
    progress = {
        "iterations": it + 1,
        "pivots": pivots,
        "position_change_mm": change,
        "settled_by_relaxation": state.relaxed,
    }
    return _report(model, torque_nm, e, pairs, last, progress, times, tooth_errors)


def _check_load_inputs(torque_nm, cam_offset_um, tol) -> None:
    if not (np.isfinite(torque_nm) and torque_nm >= 0):
        raise DesignError("torque_nm", f"must be >= 0 N m, got {torque_nm:g}")
    if not (np.isfinite(cam_offset_um) and cam_offset_um >= 0):
        raise DesignError("cam_offset_um", f"must be >= 0 um, got {cam_offset_um:g}")
    if not tol > 0:
        raise DesignError("tol", f"must be > 0 mm, got {tol:g}")


@record
class _Iterate:
    """The fixed-point iteration's state between linearisations: the loads on the rim, the rim's rigid-body
    position, the ball and tooth forces, which teeth carried load, and the relaxation."""

    loads: np.ndarray
    rigid: np.ndarray
    F_ball: np.ndarray
    F_teeth: np.ndarray
    active: np.ndarray
    acc: Anderson
    omega: float = 1.0
    last_change: float = np.inf
    settled: int = 0
    relaxed: bool = False

    def settled_after(self, change: float, tol: float) -> bool:
        """A contact toggling between passes (a linearisation that closes a pair the exact geometry opens) has no
        fixed point: the relaxed passes settle where it switches (three in a row below a quarter of the tolerance
        once scaled by the relaxation); the residual of the nonlinear contact law on the exact geometry is then
        reported (linearisation_mm)."""
        self.settled = self.settled + 1 if (self.omega < 1.0 and change * self.omega < 0.25 * tol) else 0
        self.relaxed = self.settled >= 3
        return self.relaxed

    def advance(self, it: int, change: float, tol: float, plain: _Plain) -> None:
        """The next iterate from the linearisation's solution ``plain``: Anderson-accelerated, or under-relaxed once
        the plain iteration stops contracting (the exact gaps are piecewise smooth in the poses, polygon vertices,
        which can leave a 2-cycle of sub-micrometre amplitude)."""
        cycling = it >= 5 and change > 0.95 * self.last_change  # a cycle, not a slow contraction
        # once relaxing: a step not yet settled while the change does not halve per pass relaxes further
        # (a 2-cycle's change stays near its amplitude; halving only on the passes where it grows took twice the passes)
        unsettled = self.omega < 1.0 and change > 0.5 * self.last_change and change * self.omega >= 0.25 * tol
        if cycling or unsettled:
            self.omega = max(self.omega * 0.5, _OMEGA_MIN)
            self.acc.reset()
        self.last_change = change
        w = self.omega
        if w < 1.0:
            self.loads = (1 - w) * self.loads + w * plain.loads
            self.rigid = (1 - w) * self.rigid + w * plain.rigid
            self.F_ball = (1 - w) * self.F_ball + w * plain.F_ball
            self.F_teeth = (1 - w) * self.F_teeth + w * plain.F_teeth
        else:
            self.loads, self.rigid = self.acc.step(self.loads, self.rigid, plain.loads, plain.rigid, change)
            self.F_ball = plain.F_ball.copy()
            self.F_teeth = plain.F_teeth
        self.active = plain.active


class _Plain(NamedTuple):
    """The linearisation's solution as the next iterate of the plain fixed-point iteration."""

    loads: np.ndarray
    rigid: np.ndarray
    F_ball: np.ndarray
    F_teeth: np.ndarray
    active: np.ndarray


def _start(model: ElasticModel, e: np.ndarray, warm: LoadState | None):
    """The state the iteration starts from: ring loads per table angle, rim freedoms, ball forces, measured pairs."""
    tab = model.tables
    if warm is not None:
        loads, rigid = loads_on_table(tab, warm.laws[0].psi, warm.laws[0].loads), np.array(warm.rigid)
        F_ball = warm.contacts["force"][warm.contacts["kind"] == 0].copy()
    else:
        # a cold start begins on the cam: the rim pressed onto it by the balls alone (no teeth, no torque)
        mnt = mounted(model, e)
        loads, rigid, F_ball = mnt.loads.copy(), mnt.rigid.copy(), mnt.force.copy()
    # a warm start's pairs were measured at exactly its state: the first pass measures only what moves
    if warm is not None and warm.pairs is not None and warm.pairs.model is model:
        return loads, rigid, F_ball, warm.pairs.copy()
    # a cold start's first pass is the mounted state: its pairs are measured once per model and cam offset
    key = ("mounted_pairs", float(e[0]), float(e[1]))
    if key not in model.cache:
        nominal = MeasuredPairs(model)
        rot0, shift0, origin0, el0, cand0 = tooth_poses(model, loads, rigid)
        nominal.update(rot0, shift0, origin0, el0, cand0, rigid, full=True)
        model.cache[key] = nominal
    return loads, rigid, F_ball, model.cache[key].copy()


@record
class _Pass:
    """One linearisation: the pairs measured at the current poses and the contact problem's solution there."""

    keys: np.ndarray
    F: np.ndarray
    sol: object
    idx: np.ndarray
    b: np.ndarray
    f: np.ndarray
    origin: np.ndarray
    cam_shift: np.ndarray
    pivots: int
    t_geo: float
    t_sol: float


def _linearise(model, torque_nm, e, f_ext, pairs, loads, rigid, F_ball, F_teeth_prev, prev_active, it, tooth_errors):
    """Measure the contact geometry at the current loaded poses (the clearance engine) and solve the linearised
    contact problem there (docs/models.md 4.1); the first pass linearises the Hertz contacts again about the
    forces it finds before the teeth move."""
    Z = len(model.bearing.psi)
    t0 = time.perf_counter()
    rot, shift, origin, el, cand = tooth_poses(model, loads, rigid, tooth_errors)
    if cand.size == 0 and torque_nm > 0:
        raise DesignError(
            "generator.w0_coef",
            "the flexspline teeth never reach the rigid teeth (no tooth tip within "
            f"{RADIAL_MARGIN:g} mm of the rigid tip circle): no torque can be carried",
        )
    keys = pairs.update(rot, shift, origin, el, cand, rigid) if cand.size else np.zeros(0, dtype=int)
    t1 = time.perf_counter()
    idx, b, f, A, q, s_c = _assemble(model, pairs, keys, el, rigid, e, F_ball, F_teeth_prev[keys])
    M = Compliance(model.tables, idx, b * f[:, None], s_c)
    active = np.concatenate([F_ball > 0, prev_active[keys]])
    F_h = F = None  # F: the solution of the pass (set by the first solve below)
    pivots = 0
    for h in range(_HERTZ_START if it == 0 else 1):
        if h:
            if F_h is not None and np.abs(F - F_h).max() <= _HERTZ_TOL * F.max():
                break
            # the first pass: the Hertz contacts linearised again about the forces just found,
            # on the same geometry (its poses have not moved: no engine call), before the teeth move
            _, _, _, _, q, s_c = _assemble(model, pairs, keys, el, rigid, e, F[:Z], F[Z:])
            M = M.with_contact(s_c)
            active = F > 0
        try:
            sol = solve_supported(
                M,
                q,
                A,
                f_ext,
                model.support_stiffness,
                active=active if (it or h) else _first_guess(model, keys, q, Z, torque_nm),
            )
            cam_shift = sol.a[3:].copy()
            sol = replace(sol, a=sol.a[:3])
        except ContactSolveError as exc:
            if torque_nm > 0 and len(keys) and "balance" in str(exc):
                raise DesignError(
                    "generator.w0_coef",
                    f"no set of tooth contacts can carry {torque_nm:g} N m: the teeth never meet on the working flanks",
                ) from None
            raise
        pivots += sol.iterations
        F_h, F = (F if h else None), sol.F
    return _Pass(keys, F, sol, idx, b, f, origin, cam_shift, pivots, t1 - t0, time.perf_counter() - t1)


def _report(model, torque_nm, e, pairs, last, progress, times, tooth_errors) -> LoadState:
    """The loaded state of the last contact solution: contacts, residuals, the laws of the loaded rim."""
    tab = model.tables
    n_ang = len(tab.angles)
    Z = len(model.bearing.psi)
    n_keys = len(model.zs) * tab.z_g * 2
    centre = model.drive.law
    # the reported state is the last contact solution itself (not a relaxed mixture): its forces, points and
    # normals are in equilibrium to round-off; the exact gaps are then measured on the final poses
    keys, F, sol, idx, b, f, point, normal, cam_shift = last
    loads = dense_loads(n_ang, idx, F, f, b)
    rigid = sol.a.copy()
    F_ball, Ft = F[:Z], F[Z:]
    model.bearing.check(F_ball)
    t0 = time.perf_counter()
    pairs2 = pairs.copy()
    keys2, gaps2, exact2 = pairs2.report(*tooth_poses(model, loads, rigid, tooth_errors), rigid)
    times["geometry"] += time.perf_counter() - t0
    psi, law_loads = merge_loads(tab.angles, loads)
    laws = [
        LoadedLaw(centre, model.section_law(i), model.ring, psi, law_loads, model.scales[i], tuple(rigid))
        for i in range(len(model.zs))
    ]
    n_t = len(keys)
    sec_t, tooth_t = np.divmod(keys // 2, tab.z_g)
    if n_t:
        width = model.widths[sec_t]
        appr_t = model.teeth.bending(point, normal, width) * Ft + model.teeth.hertz(Ft, width)
        # a pair that left the GAP_MARGIN band on the final poses is open by at least that much
        final = np.full(n_keys, GAP_MARGIN)
        final[keys2] = gaps2
        gap_t = final[keys]
        is_exact = np.zeros(n_keys, dtype=bool)
        is_exact[keys2] = exact2
        exact_t = is_exact[keys]
    else:
        appr_t = gap_t = np.zeros(0)
        exact_t = np.zeros(0, dtype=bool)
    cb, sb = np.cos(model.bearing.psi), np.sin(model.bearing.psi)
    w_nom, v_nom, _ = tab.centre_ball
    rows = ball_rows(model, cam_excess(model), e)
    U_b = (tab.influence[3 * tab.z_g :] @ loads.ravel()).reshape(-1, 3)
    gap_b = rows.q - (rows.b * U_b).sum(axis=1) - rows.A @ np.concatenate([rigid, cam_shift])
    appr_b = model.bearing.approach(F_ball)
    # exact complementarity of the nonlinear contacts: gap + approach >= 0, F >= 0, F (gap + approach) = 0
    g_all = np.concatenate([gap_b + appr_b, gap_t + appr_t])
    F_all = np.concatenate([F_ball, Ft])
    loaded = F_all > 0
    lin = float(np.abs(g_all[loaded]).max()) if loaded.any() else 0.0
    r_b = centre.r_m + w_nom
    ball_pt = np.stack([r_b * cb - v_nom * sb, r_b * sb + v_nom * cb], axis=-1)
    empty2 = np.zeros((0, 2))
    contacts = {
        "kind": np.concatenate([np.zeros(Z, int), np.ones(n_t, int)]),
        "section": np.concatenate([np.zeros(Z, int), sec_t]),
        "tooth": np.concatenate([np.full(Z, -1), tooth_t]),
        "flank": np.concatenate([np.full(Z, -1), keys % 2]),
        "phi": np.concatenate([model.bearing.psi, tab.angles[tooth_t]]),
        "force": F_all,
        "gap": np.concatenate([gap_b, gap_t]),
        "gap_exact": np.concatenate([np.ones(Z, dtype=bool), exact_t]),
        "approach": np.concatenate([appr_b, appr_t]),
        "point": np.concatenate([ball_pt, point if n_t else empty2]),
        "normal": np.concatenate([-rows.normal, normal if n_t else empty2]),
    }
    residuals = {
        "equilibrium": sol.equilibrium,
        "complementarity": sol.complementarity,
        "linearisation_mm": lin,
        "min_gap_plus_approach_mm": float(g_all.min()) if g_all.size else 0.0,
        **progress,
    }
    # the torque the balls put on the cam (docs/models.md 4.1)
    return LoadState(
        model,
        float(torque_nm),
        e,
        laws,
        rigid,
        contacts,
        residuals,
        times,
        pairs2,
        generator_torque(rows, F_ball),
        cam_shift,
    )
