"""A catalogue-style datasheet of a drive: rated torque and the criterion that binds it, stiffness, lost motion, ratcheting, bearing life (docs/models.md 10).

Every criterion is a margin that falls with the output torque; the elastic
model is solved at torques doubling from a small one until the model stops
(the bearing's static limit, or no convergence) or every criterion has
failed, and each criterion's limit is then bracketed by bisection between
the last level that met it and the first that did not. The rated torque is
the smallest limit; a criterion still met where the model stopped has its
limit *above* that torque, which the datasheet says.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import pi

import numpy as np

from wgcad.constants import INTERFERENCE_TOL
from wgcad.elastic import build_model, solve_load
from wgcad.elastic.mesh import entry_gaps
from wgcad.errors import DesignError, ModelError
from wgcad.units import UM_PER_MM

from .fatigue import strength
from .flexspline import state_stresses, stress_setup
from .friction import friction_rows
from .life import bearing_life
from .notch import root_concentration
from .ratcheting import engagement_depth
from .stiffness import fit_three_segments, natural_frequency_hz

__all__ = ["Level", "Limit", "Datasheet", "rate_drive", "ratcheting_torque", "CRITERIA"]

#: the criteria, in the order the datasheet lists them: name -> what it asks
CRITERIA = {
    "fatigue": "Goodman safety of the flexspline (tooth roots, cup wall, the diaphragm the part set exports) at "
    "least [load] fatigue_safety_min",
    "yield": "peak von Mises stress of the flexspline below the yield strength",
    "bearing_life": "wave-generator bearing L10 at [load] input_speed_rpm at least [load] required_life_h",
    "entry_gap": "no tip interference at tooth entry (the loaded entry gap stays open)",
    "ratcheting": "ratcheting torque at least [load] ratcheting_safety_min times the torque",
    "bearing_static": "ball Hertz pressure within the ISO 76 static limit (4200 MPa)",
}
_BISECTIONS = 5
_DOUBLINGS = 9
#: the figures a level can hold, by group: a search between torques measures only the group its criterion reads
#: (the levels the datasheet lists and the rated one hold them all)
FIGURES = frozenset({"stresses", "life", "entry_gap", "depth"})
#: the group each criterion's margin reads
_READS = {"fatigue": "stresses", "yield": "stresses", "bearing_life": "life", "entry_gap": "entry_gap"}


@dataclass(frozen=True, slots=True)
class Level:
    """The figures of one solved torque (internal units: N m, mm, MPa, rad, h).

    A level solved inside a search holds only the figures of the criterion searched (:data:`FIGURES`): the
    others are None and :meth:`margins` leaves them out.
    """

    torque_nm: float
    state: object = field(repr=False)
    stresses: list | None = field(repr=False)
    safety: float | None
    yield_safety: float | None
    life_h: float | None
    life: object = field(repr=False)
    entry_gap: float | None
    depth: np.ndarray | None
    max_pressure: float | None

    def margins(self, ld) -> dict:
        """Each criterion's margin (>= 0: met) against the ``[load]`` table ``ld``, of the figures this level holds;
        ratcheting and the static limit are torques of their own."""
        out = {}
        if self.stresses is not None:
            out["fatigue"] = self.safety - ld.fatigue_safety_min
            out["yield"] = self.yield_safety - 1.0
        if self.life_h is not None:
            out["bearing_life"] = np.log(self.life_h / ld.required_life_h) if self.life_h > 0 else -np.inf
        if self.entry_gap is not None:
            out["entry_gap"] = self.entry_gap + INTERFERENCE_TOL
        return out


@dataclass(frozen=True, slots=True)
class Limit:
    """The torque at which one criterion stops being met (N m); ``above``: met up to ``torque_nm``, where the model
    stopped, so the limit lies beyond; ``note`` why the model stopped or how the figure was found; ``bracket``
    the bisection's last ``(met, failed)`` torques (N m) the interpolated limit lies between, or None."""

    criterion: str
    torque_nm: float
    above: bool
    note: str = ""
    bracket: tuple | None = None


@dataclass(slots=True)
class Datasheet:
    """The whole rating of one drive (internal units; ``report.rating`` words it)."""

    design: object
    model: object
    setup: object
    kt: object
    levels: list
    limits: dict
    rated_torque_nm: float
    binding: str
    rated: Level
    fit: object
    curve: list
    lost_motion: float
    #: twice the wind-up fit's intercept (``fit.theta0``, both ways), rad: not the audit's backlash
    windup_offset: float
    natural_frequency_hz: float | None
    ratcheting: dict
    notes: list
    timing: dict
    speed_rpm: float = 0.0
    #: the friction rows (:class:`~wgcad.rating.friction.FrictionRows`; None without a rated torque)
    friction: object = None
    #: the part set's warnings on parts the datasheet rates (a diaphragm below the fatigue criterion)
    warnings: tuple = ()


def _level(sheet_ctx, T: float, warm, offset, need=FIGURES) -> Level:
    """The level at ``T`` holding the figure groups ``need`` (a subset of :data:`FIGURES`)."""
    model, setup, br, dm, speed, ratio = sheet_ctx
    st = solve_load(model, T, offset[0], offset[1], warm=warm)
    stresses = state_stresses(setup, st) if "stresses" in need else None
    life = pressure = None
    if "life" in need:
        c = st.contacts
        F = c["force"][c["kind"] == 0]
        life = bearing_life(F, br.ball_diameter_mm, dm, br.groove_conformity, speed, ratio)
        pressure = float(model.bearing.pressure(F).max())
    gap = None
    if "entry_gap" in need:
        laws = [law.shifted(p) for p in (0.0, pi) for law in st.laws]
        gaps = [g.delta for g in entry_gaps(model.scene, laws) if np.isfinite(g.delta)]
        gap = min(gaps) if gaps else float("inf")
    return Level(
        torque_nm=float(T),
        state=st,
        stresses=stresses,
        safety=None if stresses is None else min(s.safety for s in stresses if s.rated),
        yield_safety=None if stresses is None else min(s.yield_safety for s in stresses if s.rated),
        life_h=None if life is None else life.l10_h,
        life=life,
        entry_gap=gap,
        depth=engagement_depth(st) if "depth" in need else None,
        max_pressure=pressure,
    )


@dataclass(frozen=True, slots=True)
class _Stop:
    """Why a search stopped: ``static`` when a ball reached the bearing's static limit (the model refuses the
    load), else no convergence or the search's own end."""

    why: str
    static: bool = False


def _try(ctx, T, warm, offset, need=FIGURES):
    """``(Level, None)`` or ``(None, _Stop)`` when the model cannot answer at ``T``."""
    try:
        return _level(ctx, T, warm, offset, need), None
    except DesignError as e:  # the bearing's static limit (FlexibleBearing.check)
        return None, _Stop(str(e.rule), static=True)
    except ModelError as e:
        return None, _Stop(str(e))


def _first_torque(drive) -> float:
    """A starting torque for the doubling: a tenth of ``(r_m / 80 mm)^3`` kN m (D1: 100 N m)."""
    return 100.0 * (drive.r_m / 80.0) ** 3


def _bracket(ctx, lo: Level, hi_T: float, ok, offset, need) -> tuple[float, Level]:
    """Bisect between ``lo`` (met) and ``hi_T`` (failed, or the model stopped): the highest level found met; the
    levels between hold the figure groups ``need``."""
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo.torque_nm + hi_T)
        lv, _ = _try(ctx, mid, lo.state, offset, need)
        if lv is not None and ok(lv):
            lo = lv
        else:
            hi_T = mid
    return hi_T, lo


def _limits(ctx, levels, ld, offset, ratchet_T, static: Limit) -> dict:
    out = {}
    names = ["fatigue", "yield", "bearing_life", "entry_gap"]
    for name in names:

        def ok(lv, name=name):
            return lv.margins(ld)[name] >= 0

        if not ok(levels[0]):
            out[name] = Limit(name, levels[0].torque_nm, False, "not met even at the lowest torque")
            continue
        k = next((i for i, lv in enumerate(levels) if not ok(lv)), None)
        if k is None:
            out[name] = Limit(name, static.torque_nm, True, static.note)
            continue
        need = {_READS[name]}
        hi, lo = _bracket(ctx, levels[k - 1], levels[k].torque_nm, ok, offset, need)
        # between the last level met and the first failed, the margin's zero by linear interpolation
        m_lo, m_hi = float(lo.margins(ld)[name]), None
        lv_hi, _ = _try(ctx, hi, lo.state, offset, need)
        if lv_hi is not None:
            m_hi = float(lv_hi.margins(ld)[name])
        T = lo.torque_nm if m_hi is None or m_hi >= m_lo else lo.torque_nm + (hi - lo.torque_nm) * m_lo / (m_lo - m_hi)
        note = f"bisected to {hi - lo.torque_nm:.3g} N m, then interpolated"
        out[name] = Limit(name, float(T), False, note, (float(lo.torque_nm), float(hi)))
    r_T, r_above, r_note = ratchet_T
    out["ratcheting"] = Limit("ratcheting", r_T / ld.ratcheting_safety_min, r_above, r_note)
    out["bearing_static"] = static
    return out


def _static_limit(ctx, levels, stop_T, stop: _Stop, offset) -> Limit:
    """Where the bearing's static limit stops the model (bisected), or the last torque solved when it did not."""
    if not stop.static:
        return Limit("bearing_static", levels[-1].torque_nm, True, stop.why)
    hi, lo = _bracket(ctx, levels[-1], stop_T, lambda lv: True, offset, need=())
    return Limit(
        "bearing_static",
        0.5 * (lo.torque_nm + hi),
        False,
        f"a ball reaches the ISO 76 static pressure limit (4200 MPa) between {lo.torque_nm:.0f} and {hi:.0f} N m",
    )


def _doubling(ctx, drive, offset, progress=None, stop_when=None, need=FIGURES) -> tuple[list, _Stop, float]:
    """Levels at zero and at torques doubling from :func:`_first_torque`, until the model stops or ``stop_when(level)``;
    returns the levels (holding the figure groups ``need``), why the search stopped and the torque the model could
    not solve (inf if none)."""
    first, why = _try(ctx, 0.0, None, offset, need)
    if first is None:
        raise ModelError(f"the unloaded drive does not solve: {why.why}")
    levels = [first]
    T = _first_torque(drive)
    for k in range(_DOUBLINGS):
        lv, why = _try(ctx, T, levels[-1].state, offset, need)
        if progress:
            progress(0.05 + 0.45 * (k + 1) / _DOUBLINGS, "torque levels")
        if lv is None:
            return levels, why, T
        levels.append(lv)
        if stop_when is not None and stop_when(lv):
            return levels, _Stop(f"every criterion failed by {T:.0f} N m"), float("inf")
        T *= 2.0
    return levels, _Stop(f"the search stopped at {levels[-1].torque_nm:.0f} N m"), float("inf")


def _ratcheting(ctx, levels, static: Limit, offset, stop_T: float = float("inf")) -> tuple:
    """The torque at which a wave's deepest tip leaves mesh (bisected), or, when none does, the torque where the
    model stops (a non-converging model is bisected too: its last converged torque and depth are reported)."""
    k = next((i for i, lv in enumerate(levels) if lv.depth.min() <= 0), None)
    if k == 0:
        return 0.0, False, "out of mesh at no load"
    if k is None and not (np.isfinite(stop_T) and static.above):  # above: the model stopped short of the limit
        return static.torque_nm, True, f"still in mesh where the model stops ({static.note})"
    lo, hi = levels[-1 if k is None else k - 1], stop_T if k is None else levels[k].torque_nm
    out_of_mesh = k is not None
    for _ in range(_BISECTIONS + 2):
        mid = 0.5 * (lo.torque_nm + hi)
        m, _ = _try(ctx, mid, lo.state, offset, {"depth"})
        if m is not None and m.depth.min() > 0:
            lo = m
        else:
            hi = mid
            out_of_mesh |= m is not None
    if out_of_mesh:
        return 0.5 * (lo.torque_nm + hi), False, f"a wave leaves mesh between {lo.torque_nm:.0f} and {hi:.0f} N m"
    return (
        lo.torque_nm,
        True,
        (
            f"the model stops converging between {lo.torque_nm:.0f} and {hi:.0f} N m with "
            f"{UM_PER_MM * lo.depth.min():.0f} um of engagement left (teeth climbing their flanks: skipping may begin there)"
        ),
    )


def _wind_up(ctx, first: Level, rated_T: float, offset, progress):
    """The wind-up at 14 torques up to the rated one, its three-segment fit, the lost motion, the rated level and the
    curve's states (the unloaded one first)."""
    model = ctx[0]
    curve_T = [0.01 * rated_T, 0.04 * rated_T] + [rated_T * j / 12.0 for j in range(1, 13)]
    curve, warm, states = [], first.state, [first.state]
    if progress:
        progress(0.8, "wind-up curve")
    for j, T in enumerate(sorted(curve_T)):
        st = solve_load(model, T, offset[0], offset[1], warm=warm)
        warm = st
        states.append(st)
        curve.append((T, st.wind_up))
        if progress:
            progress(0.8 + 0.2 * (j + 1) / len(curve_T), "wind-up curve")
    rated = _level(ctx, rated_T, warm, offset)
    Ts = np.array([c[0] for c in curve])
    th = np.array([c[1] for c in curve])
    return fit_three_segments(Ts, th), curve, 2.0 * float(np.interp(0.04 * rated_T, Ts, th)), rated, states


def _context(drive, sections: int, speed: float):
    """What every level of one drive needs: model, stress set-up, bearing, its pitch diameter, speed, ratio; and the
    root's concentration."""
    d = drive.design
    st_ = strength(d.material, d.flexspline.rim_thickness, d.drive.face_width)
    kt = root_concentration(drive.flex, drive.flex_rim_radius)
    setup = stress_setup(drive, kt.kt, st_)
    p = setup.plate  # the part set's diaphragm: the model tilts on the plate the datasheet rates
    model = build_model(drive, sections, plate=None if p is None else (p.r_i, p.r_o, p.h))
    br = d.bearing
    dm = 2.0 * (drive.flex_rim_radius - br.outer_ring_thickness_mm) - br.ball_diameter_mm
    return (model, setup, br, dm, speed, float(model.scene.ratios["u_hg"])), kt


def ratcheting_torque(drive, cam_offset_um: float = 0.0, cam_offset_deg: float = 0.0, sections: int = 3) -> tuple:
    """``(torque_nm, above, note)``: where a wave of ``drive`` leaves mesh under load (bisected between doubling
    torques), or, ``above`` True, the torque where the model stopped with every wave still in mesh."""
    ctx, _ = _context(drive, sections, drive.design.load.input_speed_rpm)
    offset = (cam_offset_um, cam_offset_deg)
    levels, stop, stop_T = _doubling(ctx, drive, offset, stop_when=lambda lv: lv.depth.min() <= 0, need={"depth"})
    return _ratcheting(ctx, levels, _static_limit(ctx, levels, stop_T, stop, offset), offset, stop_T)


def rate_drive(drive, speed_rpm: float | None = None, sections: int = 3, progress=None, cam_offset=None) -> Datasheet:
    """The datasheet of ``drive`` (needs ``[bearing]`` and ``[material] ultimate_strength_mpa``).

    ``speed_rpm`` and ``cam_offset`` (``(um, deg)``) replace ``[load]`` input_speed_rpm and cam_offset_um/_deg;
    ``progress(fraction, stage)`` is called as the work goes.

    Raises :class:`DesignError` for missing or contradictory data, :class:`ModelError` when the model cannot
    solve the unloaded drive.
    """
    t0 = time.perf_counter()
    d = drive.design
    speed = d.load.input_speed_rpm if speed_rpm is None else float(speed_rpm)
    ctx, kt = _context(drive, sections, speed)
    model, setup = ctx[0], ctx[1]
    offset = (d.load.cam_offset_um, d.load.cam_offset_deg) if cam_offset is None else tuple(map(float, cam_offset))
    t_setup = time.perf_counter() - t0

    # levels: zero, then doubling until the model stops or every criterion has failed
    levels, stop, stop_T = _doubling(
        ctx, drive, offset, progress, stop_when=lambda lv: all(v < 0 for v in lv.margins(d.load).values())
    )
    static = _static_limit(ctx, levels, stop_T, stop, offset)
    r = _ratcheting(ctx, levels, static, offset, stop_T)
    ratchet = {"offset_um": offset[0], "offset_deg": offset[1], "torque_nm": r[0], "above": r[1], "note": r[2]}
    if offset[0] > 0:
        r0 = ratcheting_torque(drive, 0.0, 0.0, sections)
        ratchet["no_offset"] = {"torque_nm": r0[0], "above": r0[1], "note": r0[2]}
    if progress:
        progress(0.55, "limits")
    limits = _limits(ctx, levels, d.load, offset, r, static)
    first = levels[0]
    binding = min(limits, key=lambda k: (limits[k].torque_nm, limits[k].above))
    rated_T = limits[binding].torque_nm
    t_limits = time.perf_counter() - t0 - t_setup

    # the wind-up curve up to the rated torque, for the catalogue's stiffness segments and the lost motion
    friction = None
    if rated_T > 0:
        fit, curve, lm, rated, curve_states = _wind_up(ctx, first, rated_T, offset, progress)
        # efficiency over the catalogue's range: every state solved up to the rated torque
        below = [lv.state for lv in levels if lv.torque_nm < rated_T]
        friction = friction_rows(model, ctx[3], speed, below + curve_states[1:], curve_states, rated.state)
    else:  # a criterion fails at no load: no torque to rate, nothing to fit
        fit, curve, lm, rated = None, [], None, first
    notes = []
    if setup.t_cup is None:
        notes.append("the cup wall: the design has no cup ([generator] cone_length)")
    if setup.plate is not None:
        p = setup.plate
        notes.append(
            f"the diaphragm's joints: taken rigid (clamped at the bolt circle, r = {p.r_i:.1f} mm; joined to the wall "
            f"at {p.r_o:.1f} mm, {p.h:g} mm thick: the part set's sizes, wgcad parts), no stress concentration at either; the bolt holes; the wall's own "
            "bending near the joint; the output flange"
        )
    else:
        notes.append("the output flange")
    notes.append("the bearing's own rings in bending and the cam: only the ball contacts are rated")
    if d.imperfections.any:
        notes.append(
            "[imperfections]: the datasheet rates the nominal drive (their effect under load: wgcad ke --torque-nm)"
        )
    J = d.load.output_inertia_kg_m2
    fn = natural_frequency_hz(fit.k1, J) if J is not None and fit is not None and np.isfinite(fit.k1) else None
    return Datasheet(
        design=d,
        model=model,
        setup=setup,
        kt=kt,
        levels=levels,
        limits=limits,
        rated_torque_nm=float(rated_T),
        binding=binding,
        rated=rated,
        fit=fit,
        curve=curve,
        lost_motion=lm,
        windup_offset=None if fit is None else 2.0 * fit.theta0,
        natural_frequency_hz=fn,
        ratcheting=ratchet,
        notes=notes,
        timing={"setup_s": t_setup, "limits_s": t_limits, "total_s": time.perf_counter() - t0},
        speed_rpm=speed,
        friction=friction,
        warnings=tuple(setup.plate_warnings),
    )
