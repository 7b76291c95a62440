"""One load state of the drive: contact problem re-linearised on the exact tooth geometry until the teeth stop moving (docs/models.md 4, 4.1)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from wgcad.errors import DesignError

from .anderson import Anderson
from .cam import ball_rows, cam_excess, field_displacement, generator_torque, mounted
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
from .supports import Motion
from .tables import Compliance

__all__ = ["LoadState", "solve_load", "POSITION_TOL", "RADIAL_MARGIN", "GAP_MARGIN", "STEP_LIMIT"]

#: Re-linearisation stops when no tooth moves by more than this between two
#: solutions, mm (0.2 um: a fifth of the 1 um chord tolerance of the outlines.
#: The gaps are exact for the polygons, whose contact points move from edge to
#: edge: below ~0.1 um the iteration sees that discreteness, not the drive).
POSITION_TOL = 2e-4
#: Contact forces below this are floored when the Hertz secants are taken, N
#: (the approach error it leaves is below 1e-5 mm for the balls and teeth of D1).
FORCE_FLOOR = 1e-2
_MAX_LINEARISATIONS = 100
#: Largest move of a tooth one pass may take, mm: a longer step is shortened to it (the radial margin within which
#: teeth are considered, RADIAL_MARGIN: beyond it the linearisation knows nothing).
STEP_LIMIT = 0.2
#: Smallest relaxation of a cycling re-linearisation: its steps shrink to this share of the plain step.
_OMEGA_MIN = 1.0 / 256.0
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
#: the shares of the torque a cold start passes through before the full torque (each warm-starting the next)
_RAMP = (0.25, 0.5)
_TRACE = None  # a list to record (pass, change, relaxation, pairs, loaded contacts) while debugging


@dataclass(frozen=True, slots=True)
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
        Rim translation ``dx, dy`` (mm) and rotation (rad, counter-clockwise) relative to the rigid gear at the
        generator's centre plane (the ball plane).
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
    #: where every member stands (:class:`~wgcad.elastic.supports.Motion`: the rim and rigid gear at each plane,
    #: the cam against its support)
    motion: object = None
    #: the freedoms of the contact problem (``model.supports.names``), mm and rad
    freedoms: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def cam_shift(self) -> np.ndarray:
        """The cam's motion against its support, mm (generator frame; zero when it is held)."""
        return self.motion.cam if self.motion is not None else np.zeros(2)

    @property
    def mesh_wind_up(self) -> float:
        """Rotation of the toothed rim against the rigid gear at the generator's centre plane, rad (signed so that
        it grows with torque)."""
        return float(self.model.torque_sign * self.rigid[2])

    @property
    def output_rotation(self) -> float:
        """The output's rotation against the rigid gear, rad (counter-clockwise): the diaphragm's (spatial rim) or
        the rim's plus the cup's twist in series (planar), docs/models.md 4.2."""
        sup = self.model.supports
        return sup.output_rotation(self.freedoms, self.model.torque_sign * 1e3 * self.torque_nm)

    @property
    def wind_up(self) -> float:
        """Output wind-up, rad (signed so that it grows with torque)."""
        return float(self.model.torque_sign * self.output_rotation)

    def law(self, section: int = 0) -> LoadedLaw:
        return self.laws[section]

    def zone_torque(self) -> np.ndarray:
        """The torque each engagement zone carries, N mm ``(waves,)``: the tooth forces' moments about the axis by
        the wave their tooth belongs to (docs/models.md 4.2), signed like the output torque."""
        c = self.contacts
        t = c["kind"] == 1
        n_w = self.model.drive.design.drive.waves
        # the wave a tooth belongs to: the nearest major axis (at 2 pi k / n_w from the generator's)
        wave = np.mod(np.round(c["phi"][t] * n_w / (2.0 * np.pi)), n_w).astype(int)
        p, n = c["point"][t], c["normal"][t]
        moment = -c["force"][t] * (p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0])
        out = np.zeros(n_w)
        np.add.at(out, wave, moment)
        return -out * self.model.torque_sign

    def zone_share(self) -> np.ndarray:
        """Each zone's share of the tooth torque ``(waves,)`` (sums to 1; NaN without tooth load)."""
        z = self.zone_torque()
        tot = float(z.sum())
        return z / tot if tot > 0 else np.full(len(z), np.nan)


def _cam_offset(e_um: float, e_deg: float) -> np.ndarray:
    e = 1e-3 * e_um
    a = np.deg2rad(e_deg)
    return np.array([e * np.cos(a), e * np.sin(a)])


def _geometry(model: ElasticModel, loads: np.ndarray, motion: Motion):
    """Every tooth pair within GAP_MARGIN measured on the exact geometry at the state ``(loads, motion)``: keys, gaps, pairs."""
    rot, shift, origin, el, cand = tooth_poses(model, loads, motion.sections)
    pairs = MeasuredPairs(model)
    sec = motion.sections
    keys = pairs.update(rot, shift, origin, el, cand, sec, full=True) if cand.size else np.zeros(0, dtype=int)
    return keys, pairs.gap[keys], pairs


class _Problem(NamedTuple):
    """The linearised contact problem of a pass (balls first, then the tooth pairs ``keys``)."""

    idx: np.ndarray  # angle index of each contact in the ring's tables
    b: np.ndarray  # (m, 3) how a unit force loads the ring
    f: np.ndarray  # (m,) coning weight
    A: np.ndarray  # (m, r) freedom columns
    q: np.ndarray  # (m,) gap at zero force and zero motion (Hertz offsets included)
    s: np.ndarray  # (m,) contact compliances
    field: object  # (U, W) of the cup, or None


def _assemble(model: ElasticModel, pairs: MeasuredPairs, keys, e, F_prev_ball, F_prev_teeth) -> _Problem:
    """The linearised contact problem: balls along the cam's normals, the rim round when unloaded (cam.ball_rows,
    docs/models.md 4.1), then the tooth pairs ``keys`` as measured; every contact's freedom columns and the cup's
    field from its plane (docs/models.md 4.2)."""
    br = model.bearing
    tab = model.tables
    sup = model.supports
    Z = len(br.psi)
    rows = ball_rows(model, cam_excess(model), e)
    idx_b = tab.z_g + np.arange(Z)
    o_b, s_b = br.tangent(F_prev_ball, FORCE_FLOOR)
    q_b = rows.q + o_b
    sec, tooth = np.divmod(keys // 2, tab.z_g)
    n_t = len(keys)
    A3 = np.concatenate([rows.A[:, :3], pairs.A[keys]])
    cam = np.concatenate([rows.A[:, 3:5], np.zeros((n_t, 2))])
    plane = np.concatenate([np.full(Z, sup.ball_plane), sec])
    is_tooth = np.concatenate([np.zeros(Z, dtype=bool), np.ones(n_t, dtype=bool)])
    A = sup.columns(A3, cam, plane, is_tooth)
    fld = sup.field(A3, plane)
    if n_t == 0:
        return _Problem(idx_b, rows.b, np.ones(Z), A, q_b, s_b, fld)
    f_t = model.scales[sec]
    width = model.widths[sec]
    o_t, s_t = model.teeth.tangent(F_prev_teeth, width, FORCE_FLOOR)
    s_t = s_t + model.teeth.bending(pairs.point[keys], pairs.normal[keys], width)
    q_t = pairs.q_geo[keys] + o_t
    return _Problem(
        np.concatenate([idx_b, tooth]),
        np.concatenate([rows.b, pairs.b[keys]]),
        np.concatenate([np.ones(Z), f_t]),
        A,
        np.concatenate([q_b, q_t]),
        np.concatenate([s_b, s_t]),
        fld,
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
    ramp: bool = True,
    exact_report: bool = True,
) -> LoadState:
    """Solve the drive under output torque ``torque_nm`` with the cam axis offset by ``cam_offset_um`` at ``cam_offset_deg``.

    Generator at angle 0 (major axis on +x, tooth 0 on it, rigid gear's teeth as the design places them).
    Each pass: exact contact geometry of every tooth near engagement from the
    clearance engine at the current loaded poses; the linearised problem
    ``gap = q + (D + diag(s) + U W U') F - A a >= 0, F >= 0, F gap = 0`` with the
    freedoms ``a`` of every member free, held or sprung (``D`` the ring compliance, ``s`` the ball and tooth
    secant compliances, ``U W U'`` the cup's bending and twist between planes; docs/models.md 4.1, 4.2); then the
    poses are updated and the pass repeated until no tooth moves by more than ``tol`` (mm).

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
    eccentricities); the cam offset stays the physical input above. A cold start (no ``warm``) brings the
    torque up in steps (``ramp``). ``exact_report`` False leaves the final measurement of the open pairs out
    (their gaps the last linearisation's): a run that needs only the motions and forces (the loaded KE).
    """
    _check_load_inputs(torque_nm, cam_offset_um, tol)
    if warm is None and torque_nm > 0 and ramp:
        warm = _ramp(model, torque_nm, cam_offset_um, cam_offset_deg, tol, tooth_errors)
    e = _cam_offset(cam_offset_um, cam_offset_deg)
    sup = model.supports
    f_ext = sup.f_ext(model.torque_sign * 1e3 * torque_nm)
    Z = len(model.bearing.psi)
    n_keys = len(model.zs) * model.tables.z_g * 2
    loads, motion, F_ball, pairs = _start(model, e, warm)
    F_teeth = _warm_teeth(model, warm, n_keys, float(torque_nm))
    acc = Anderson(model.drive.r_m, ANDERSON_DEPTH, len(sup.planes))
    state = _Iterate(loads, motion, F_ball, F_teeth, F_teeth > 0, acc)
    times = {"geometry": 0.0, "solver": 0.0}
    pivots = 0
    change = 0.0
    for it in range(_MAX_LINEARISATIONS):
        lin = _linearise(model, torque_nm, e, f_ext, pairs, state, it, tooth_errors)
        keys, F = lin.keys, lin.F
        pivots += lin.pivots
        times["geometry"] += lin.t_geo
        times["solver"] += lin.t_sol
        last = (keys, F, lin, pairs.point[keys], pairs.normal[keys])
        loads_new = dense_loads(len(model.tables.angles), lin.prob.idx, F, lin.prob.f, lin.prob.b)
        F_t_new = np.zeros(n_keys)
        F_t_new[keys] = F[Z:]
        change = _change(model, loads_new, lin, state.motion, tooth_errors)
        if _TRACE is not None:
            _TRACE.append((it, change, state.omega, len(keys), int((F > 0).sum())))
        if change < tol or state.settled_after(change, tol):
            break
        active = np.zeros(n_keys, dtype=bool)
        active[keys] = F[Z:] > 0
        state.advance(it, change, tol, _Plain(loads_new, lin.motion, F[:Z], F_t_new, active))
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
    return _report(model, torque_nm, e, pairs, last, progress, times, tooth_errors, exact_report)


def _change(model, loads_new, lin: _Pass, motion: Motion, tooth_errors) -> float:
    """The largest move of an engaging tooth from the linearisation's poses to the solution's, mm (the fixed-point
    residual itself, from the tables: no engine call), and of the rim's rotation at its radius."""
    o_new = tooth_origins(model, loads_new, lin.motion.sections, tooth_errors)
    k2 = lin.keys // 2
    d = np.hypot(*(o_new[k2] - lin.origin[k2]).T)
    d_rot = np.abs(lin.motion.rim[:, 2] - motion.rim[:, 2]).max() * model.drive.r_m
    return max(float(d.max()) if d.size else 0.0, float(d_rot))


def _ramp(model, torque_nm, cam_offset_um, cam_offset_deg, tol, tooth_errors) -> LoadState:
    """The states a cold start passes through first. At full torque one linearisation about the unloaded rim would
    carry it all: on soft supports the first passes then swing the members by hundreds of micrometres. The
    torque is brought up in steps instead, each state warm-starting the next (the fixed point is the same)."""
    warm = None
    for share in _RAMP:
        warm = solve_load(
            model,
            share * torque_nm,
            cam_offset_um,
            cam_offset_deg,
            tol,
            warm,
            tooth_errors,
            ramp=False,
            exact_report=False,
        )
    return warm


def _check_load_inputs(torque_nm, cam_offset_um, tol) -> None:
    if not (np.isfinite(torque_nm) and torque_nm >= 0):
        raise DesignError("torque_nm", f"must be >= 0 N m, got {torque_nm:g}")
    if not (np.isfinite(cam_offset_um) and cam_offset_um >= 0):
        raise DesignError("cam_offset_um", f"must be >= 0 um, got {cam_offset_um:g}")
    if not tol > 0:
        raise DesignError("tol", f"must be > 0 mm, got {tol:g}")


@dataclass(slots=True)
class _Iterate:
    """The fixed-point iteration's state between linearisations: the loads on the rim, where the members stand,
    the ball and tooth forces, which teeth carried load, and the relaxation."""

    loads: np.ndarray
    motion: Motion
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
        if change > STEP_LIMIT:
            # a pass that would swing the teeth by more than the radial margin (a warm start from a state far off, a
            # soft member): the linearisation does not reach that far, so only that far is taken (the fixed point
            # is the same; the acceleration starts afresh)
            w = min(w, STEP_LIMIT / change)
            self.acc.reset()
        if w < 1.0:
            self.loads = (1 - w) * self.loads + w * plain.loads
            self.motion = self.motion.mix(plain.motion, w)
            self.F_ball = (1 - w) * self.F_ball + w * plain.F_ball
            self.F_teeth = (1 - w) * self.F_teeth + w * plain.F_teeth
        else:
            self.loads, self.motion = self.acc.step(self.loads, self.motion, plain.loads, plain.motion, change)
            self.F_ball = plain.F_ball.copy()
            self.F_teeth = plain.F_teeth
        self.active = plain.active


class _Plain(NamedTuple):
    """The linearisation's solution as the next iterate of the plain fixed-point iteration."""

    loads: np.ndarray
    motion: Motion
    F_ball: np.ndarray
    F_teeth: np.ndarray
    active: np.ndarray


def _warm_teeth(model: ElasticModel, warm: LoadState | None, n_keys: int, torque_nm: float) -> np.ndarray:
    """The tooth forces of the state a run starts from at the same torque, by pair key (else zero): the first pass
    linearises the Hertz contacts about them and starts its active set from the pairs they load. From another
    torque (a ramp, a torque sweep) the first pass starts from the closed pairs and linearises again as it goes."""
    out = np.zeros(n_keys)
    if warm is not None and warm.torque_nm == torque_nm:
        c = warm.contacts
        t = c["kind"] == 1
        out[(c["section"][t] * model.tables.z_g + c["tooth"][t]) * 2 + c["flank"][t]] = c["force"][t]
    return out


def _start(model: ElasticModel, e: np.ndarray, warm: LoadState | None):
    """The state the iteration starts from: ring loads per table angle, where the members stand, ball forces,
    measured pairs."""
    tab = model.tables
    if warm is not None:
        loads, motion = loads_on_table(tab, warm.laws[0].psi, warm.laws[0].loads), warm.motion
        F_ball = warm.contacts["force"][warm.contacts["kind"] == 0].copy()
    else:
        # a cold start begins on the cam: the rim pressed onto it by the balls alone (no teeth, no torque)
        mnt = mounted(model, e)
        loads, motion, F_ball = mnt.loads.copy(), mnt.motion, mnt.force.copy()
    # a warm start's pairs were measured at exactly its state: the first pass measures only what moves
    if warm is not None and warm.pairs is not None and warm.pairs.model is model:
        return loads, motion, F_ball, warm.pairs.copy()
    # a cold start's first pass is the mounted state: its pairs are measured once per model and cam offset
    key = ("mounted_pairs", float(e[0]), float(e[1]))
    if key not in model.cache:
        nominal = MeasuredPairs(model)
        sec = motion.sections
        rot0, shift0, origin0, el0, cand0 = tooth_poses(model, loads, sec)
        nominal.update(rot0, shift0, origin0, el0, cand0, sec, full=True)
        model.cache[key] = nominal
    return loads, motion, F_ball, model.cache[key].copy()


@dataclass(slots=True)
class _Pass:
    """One linearisation: the pairs measured at the current poses and the contact problem's solution there."""

    keys: np.ndarray
    F: np.ndarray
    sol: object
    prob: _Problem
    origin: np.ndarray
    motion: Motion
    pivots: int
    t_geo: float
    t_sol: float


def _linearise(model, torque_nm, e, f_ext, pairs, state: _Iterate, it, tooth_errors):
    """Measure the contact geometry at the current loaded poses (the clearance engine) and solve the linearised
    contact problem there (docs/models.md 4.1); the first pass linearises the Hertz contacts again about the
    forces it finds before the teeth move."""
    loads, motion, F_ball, F_teeth_prev, prev_active = (
        state.loads,
        state.motion,
        state.F_ball,
        state.F_teeth,
        state.active,
    )
    Z = len(model.bearing.psi)
    t0 = time.perf_counter()
    sec = motion.sections
    rot, shift, origin, el, cand = tooth_poses(model, loads, sec, tooth_errors)
    if cand.size == 0 and torque_nm > 0:
        raise DesignError(
            "generator.w0_coef",
            "the flexspline teeth never reach the rigid teeth (no tooth tip within "
            f"{RADIAL_MARGIN:g} mm of the rigid tip circle): no torque can be carried",
        )
    keys = pairs.update(rot, shift, origin, el, cand, sec) if cand.size else np.zeros(0, dtype=int)
    t1 = time.perf_counter()
    prob = _assemble(model, pairs, keys, e, F_ball, F_teeth_prev[keys])
    M = Compliance(model.tables, prob.idx, prob.b * prob.f[:, None], prob.s)
    active = np.concatenate([F_ball > 0, prev_active[keys]])
    carried = bool(prev_active[keys].any())  # a warm start's loaded teeth: the first guess of the active set
    # F: the solution of the pass (set by the first solve below); F_h: the forces the Hertz contacts were
    # linearised about (a warm start's, else none)
    F_h = np.concatenate([F_ball, F_teeth_prev[keys]]) if carried else None
    F = None
    pivots = 0
    q = prob.q
    for h in range(_HERTZ_START if it == 0 else 1):
        if h:
            if F_h is not None and np.abs(F - F_h).max() <= _HERTZ_TOL * F.max():
                break
            # the first pass: the Hertz contacts linearised again about the forces just found,
            # on the same geometry (its poses have not moved: no engine call), before the teeth move
            again = _assemble(model, pairs, keys, e, F[:Z], F[Z:])
            q = again.q
            M = M.with_contact(again.s)
            prob = prob._replace(q=q, s=again.s)
            active = F > 0
        try:
            sol = solve_supported(
                M,
                q,
                prob.A,
                f_ext,
                model.support_stiffness,
                active=active if (it or h or carried) else _first_guess(model, keys, q, Z, torque_nm),
                field=prob.field,
            )
        except ContactSolveError as exc:
            if torque_nm > 0 and len(keys) and "balance" in str(exc):
                raise DesignError(
                    "generator.w0_coef",
                    f"no set of tooth contacts can carry {torque_nm:g} N m: the teeth never meet on the working flanks",
                ) from None
            raise
        pivots += sol.iterations
        F_h, F = (F if h else F_h), sol.F
    new_motion = model.supports.plane_motion(sol.a, field_displacement(prob.field, F))
    return _Pass(keys, F, sol, prob, origin, new_motion, pivots, t1 - t0, time.perf_counter() - t1)


def _report(model, torque_nm, e, pairs, last, progress, times, tooth_errors, exact: bool = True) -> LoadState:
    """The loaded state of the last contact solution: contacts, residuals, the laws of the loaded rim. ``exact``
    False: the tooth gaps are the last linearisation's (no measurement at the final poses; ``gap_exact`` False
    and the nonlinear residual not checked, NaN)."""
    tab = model.tables
    n_ang = len(tab.angles)
    Z = len(model.bearing.psi)
    n_keys = len(model.zs) * tab.z_g * 2
    centre = model.drive.law
    # the reported state is the last contact solution itself (not a relaxed mixture): its forces, points and
    # normals are in equilibrium to round-off; the exact gaps are then measured on the final poses
    keys, F, lin, point, normal = last
    sol, prob, motion = lin.sol, lin.prob, lin.motion
    loads = dense_loads(n_ang, prob.idx, F, prob.f, prob.b)
    sec_motion = motion.sections
    F_ball, Ft = F[:Z], F[Z:]
    model.bearing.check(F_ball)
    t0 = time.perf_counter()
    pairs2 = pairs.copy()
    if exact:
        keys2, gaps2, exact2 = pairs2.report(*tooth_poses(model, loads, sec_motion, tooth_errors), sec_motion)
    else:
        keys2 = keys
        gaps2 = sol.gap[Z:] - (model.teeth.bending(point, normal, model.widths[(keys // 2) // tab.z_g]) * F[Z:])
        gaps2 = gaps2 - model.teeth.hertz(F[Z:], model.widths[(keys // 2) // tab.z_g])
        exact2 = np.zeros(len(keys), dtype=bool)
    times["geometry"] += time.perf_counter() - t0
    psi, law_loads = merge_loads(tab.angles, loads)
    laws = [
        LoadedLaw(centre, model.section_law(i), model.ring, psi, law_loads, model.scales[i], tuple(sec_motion[i]))
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
    gap_b = rows.q - (rows.b * U_b).sum(axis=1) - rows.A @ np.concatenate([motion.ball, motion.cam])
    appr_b = model.bearing.approach(F_ball)
    # exact complementarity of the nonlinear contacts: gap + approach >= 0, F >= 0, F (gap + approach) = 0
    g_all = np.concatenate([gap_b + appr_b, gap_t + appr_t])
    F_all = np.concatenate([F_ball, Ft])
    loaded = F_all > 0
    lin_res = (float(np.abs(g_all[loaded]).max()) if loaded.any() else 0.0) if exact else float("nan")
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
        "linearisation_mm": lin_res,
        "min_gap_plus_approach_mm": float(g_all.min()) if g_all.size else 0.0,
        **progress,
    }
    # the torque the balls put on the cam (docs/models.md 4.1)
    return LoadState(
        model,
        float(torque_nm),
        e,
        laws,
        motion.centre,
        contacts,
        residuals,
        times,
        pairs2,
        generator_torque(rows, F_ball),
        motion,
        np.asarray(sol.a, dtype=float),
    )
