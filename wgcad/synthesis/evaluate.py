"""One candidate of a design search, judged against the requirements, cheapest check first (docs/models.md 14).

Stages, each run only when the ones before it passed (a candidate that fails one is not worth the next):

1. ``ratio``: ``z_flex / (z_rigid - z_flex)`` (rigid gear fixed; the flexspline fixed:
   ``z_rigid / (z_rigid - z_flex)``) against the required ratio; tooth counts only.
2. ``design rules``: the design's own field rules and derived geometry (:func:`wgcad.drive.build_drive`: pointed or
   undercut teeth, fillets that do not fit, teeth that never meet).
3. ``outside diameter``: the rigid gear's body (its rim) within the envelope, and the flexspline's length.
4. ``audit``: the no-load clearance audit (0.5 deg, 3 sections, exact): smallest clearance and backlash.
5. ``rating``: the datasheet (:func:`wgcad.rating.rate_drive`): at the rated torque fatigue, yield and bearing
   life hold; up to the peak torque the entry gap stays open, no ratcheting, the bearing within its static limit.
6. ``ke budget``: ``ke_samples`` drives drawn from the tolerances (the sweep's own sample runner, in this
   process): the share whose KE stays within ``ke_max_arcsec`` at least ``ke_yield_min`` (the sample share: a
   point estimate; the summary gives its Clopper-Pearson interval).

Every constraint is a margin, >= 0 when met, scaled so that a margin of -0.1 is "10 % short"; a stage that stops a
candidate leaves the later constraints unknown (None). Internal units (mm, N m, rad); the record's keys say which.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..clearance.engine import audit
from ..clearance.search import AuditSettings
from ..design import Design
from ..design.schema import with_changes
from ..drive import build_drive
from ..errors import DesignError, ModelError
from ..sweep.tasks import run_batch
from .requirements import ke_spec

__all__ = ["Evaluation", "evaluate", "apply", "STAGES"]

STAGES = ("ratio", "design rules", "outside diameter", "audit", "rating", "ke budget")

#: the continuous-duty criteria of the datasheet (they must hold at the rated torque) and the momentary ones (up to
#: the peak torque): wgcad.rating.datasheet's limit names
RATED = ("fatigue", "yield", "bearing_life")
PEAK = ("entry_gap", "ratcheting", "bearing_static", "yield")


@dataclass(slots=True)
class Evaluation:
    """The judgement of one candidate: the free keys' values, each constraint's margin (>= 0: met; None: not reached),
    the objectives' values where they were computed, the stage it stopped at and why."""

    values: dict
    margins: dict = field(default_factory=dict)
    objectives: dict = field(default_factory=dict)
    stage: str = "ratio"
    feasible: bool = False
    message: str = ""
    seconds: float = 0.0
    #: wall seconds of each stage the candidate reached that does work (design rules, audit, rating, ke budget)
    stage_seconds: dict = field(default_factory=dict)

    @property
    def worst(self) -> tuple[str, float] | None:
        """The constraint with the smallest margin, or None before any was measured."""
        known = {k: v for k, v in self.margins.items() if v is not None}
        return min(known.items(), key=lambda kv: kv[1]) if known else None


def apply(base: Design, free, values: dict) -> Design:
    """The base design with the free keys set to ``values`` (``{"table.key": value}``), field rules checked."""
    tables: dict = {}
    for fk in free:
        v = values[fk.name]
        tables.setdefault(fk.table, {})[fk.key] = int(round(v)) if fk.integer else float(v)
    return with_changes(base, **tables)


def _ratio_of(z_flex: int, z_rigid: int, fixed: str) -> float:
    """Reduction ratio, input (generator) to output: ``z_flex / |z_rigid - z_flex|`` with the rigid gear fixed,
    ``z_rigid / |z_rigid - z_flex|`` with the flexspline fixed (docs/models.md 1)."""
    diff = abs(z_rigid - z_flex)
    if diff == 0:
        return math.inf
    return (z_flex if fixed == "rigid" else z_rigid) / diff


def evaluate(base: Design, free, values: dict, req) -> Evaluation:
    """Judge the candidate ``values`` of the free keys against the requirements ``req`` (module docstring)."""
    t0 = time.perf_counter()
    ev = Evaluation(values=dict(values))
    try:
        _run(base, free, ev, req)
    finally:
        ev.seconds = time.perf_counter() - t0
    return ev


def _run(base, free, ev: Evaluation, req) -> None:
    if req.ratio is not None:  # from the tooth counts alone, before any rule is checked
        dr = base.drive
        z_f = int(round(ev.values.get("drive.z_flex", dr.z_flex)))
        z_r = int(round(ev.values.get("drive.z_rigid", dr.z_rigid)))
        ratio = _ratio_of(z_f, z_r, dr.fixed)
        ev.margins["ratio"] = -abs(ratio - req.ratio) / req.ratio
        if ev.margins["ratio"] < -1e-12:
            ev.stage, ev.message = "ratio", f"ratio {ratio:g}, required {req.ratio:g}"
            return
        ev.margins["ratio"] = 0.0
    ev.stage = "design rules"
    t = time.perf_counter()
    try:
        drive = build_drive(apply(base, free, ev.values))
    except DesignError as e:
        ev.margins["design rules"] = -1.0
        ev.message = f"{e.field}: {e.rule}"
        return
    finally:
        ev.stage_seconds["design rules"] = time.perf_counter() - t
    ev.margins["design rules"] = 0.0
    ev.stage = "outside diameter"
    od = 2.0 * drive.rigid_rim_radius
    ev.objectives["outside_diameter"] = od
    if req.max_outside_diameter_mm is not None:
        ev.margins["outside diameter"] = (req.max_outside_diameter_mm - od) / req.max_outside_diameter_mm
        if ev.margins["outside diameter"] < 0:
            ev.message = f"rigid gear body {od:.1f} mm across, allowed {req.max_outside_diameter_mm:g}"
            return
    if req.max_length_mm is not None:
        g = drive.design.generator
        length = g.cone_length if g.cone_length is not None else drive.design.drive.face_width
        ev.objectives["length"] = float(length)
        ev.margins["length"] = (req.max_length_mm - length) / req.max_length_mm
        if ev.margins["length"] < 0:
            ev.message = f"flexspline {length:g} mm long, allowed {req.max_length_mm:g}"
            return
    ev.stage = "audit"
    if not _timed(ev, "audit", _audit, drive, ev, req):
        return
    if req.needs_rating:
        ev.stage = "rating"
        if not _timed(ev, "rating", _rating, drive, ev, req):
            return
    if req.ke_max_arcsec is not None:
        ev.stage = "ke budget"
        if not _timed(ev, "ke budget", _ke_budget, free, ev, req):
            return
    ev.stage, ev.feasible = "done", True


def _timed(ev: Evaluation, stage: str, fn, *args) -> bool:
    """``fn(*args)``, its wall seconds kept as the stage's (an error's too: the stage ran)."""
    t = time.perf_counter()
    try:
        return fn(*args)
    finally:
        ev.stage_seconds[stage] = time.perf_counter() - t


def _audit(drive, ev: Evaluation, req) -> bool:
    zs = [0.0, 0.5 * drive.design.drive.face_width, drive.design.drive.face_width] if drive.coned else [0.0]
    res = audit(drive, AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=np.array(zs)))
    c_um = 1e3 * res.min_clearance
    ev.objectives["min_clearance"] = c_um
    bl = float(np.rad2deg(res.backlash) * 60.0) if np.isfinite(res.backlash) else None
    if bl is not None:
        ev.objectives["backlash"] = bl
    need = 0.0 if req.min_clearance_um is None else req.min_clearance_um
    # a micrometre short is 10 % short: clearances are tens of micrometres
    ev.margins["clearance"] = 0.1 * (c_um - need)
    if req.max_backlash_arcmin is not None:
        ev.margins["backlash"] = (
            req.max_backlash_arcmin - (bl if bl is not None else math.inf)
        ) / req.max_backlash_arcmin
    bad = [k for k in ("clearance", "backlash") if k in ev.margins and ev.margins[k] < 0]
    if bad:
        ev.message = f"no-load audit: smallest clearance {c_um:+.2f} um" + (
            f", backlash {bl:.2f} arcmin" if bl is not None else ", no backlash (interference)"
        )
        return False
    return True


def candidate_data(base_data: dict, free, values: dict) -> dict:
    """The base design's TOML data with the free keys set (what a sweep of the candidate starts from)."""
    data = copy.deepcopy(base_data)
    for fk in free:
        v = values[fk.name]
        data.setdefault(fk.table, {})[fk.key] = int(round(v)) if fk.integer else float(v)
    return data


def _ke_budget(free, ev: Evaluation, req) -> bool:
    spec = ke_spec(
        req.tolerances,
        candidate_data(req.base_data, free, ev.values),
        req.ke_samples,
        req.seed,
        req.ke_max_arcsec,
        "candidate",
    )
    cols = run_batch(spec.payload(), 0, spec.total)["columns"]
    within = [
        s == "ok" and math.isfinite(k) and k <= req.ke_max_arcsec for k, s in zip(cols["ke_pp_arcsec"], cols["status"])
    ]
    share = sum(within) / len(within)
    kes = sorted(k for k, s in zip(cols["ke_pp_arcsec"], cols["status"]) if s == "ok" and math.isfinite(k))
    ev.objectives["ke_yield"] = share
    if kes:
        ev.objectives["ke_max_sampled_arcsec"] = kes[-1]
    ev.margins["ke budget"] = share - req.ke_yield_min
    if ev.margins["ke budget"] < 0:
        ev.message = f"KE budget: {sum(within)} of {len(within)} drawn drives within {req.ke_max_arcsec:g} arcsec"
        return False
    return True


def _rating(drive, ev: Evaluation, req) -> bool:
    from ..rating import rate_drive

    offset = None if req.cam_offset_um is None else (req.cam_offset_um, drive.design.load.cam_offset_deg)
    try:
        sheet = rate_drive(drive, cam_offset=offset)
    except (DesignError, ModelError) as e:
        ev.margins["rating"] = -1.0
        ev.message = f"rating: {e}"
        return False
    lim = sheet.limits
    ev.objectives["rated_torque"] = float(sheet.rated_torque_nm)
    if sheet.fit is not None and np.isfinite(sheet.fit.k3):
        ev.objectives["stiffness"] = float(sheet.fit.k3)
    if req.rated_torque_nm is not None:
        for k in RATED:
            if k in lim:
                ev.margins[f"{k} at rated torque"] = lim[k].torque_nm / req.rated_torque_nm - 1.0
    if req.peak_torque_nm is not None:
        for k in PEAK:
            if k in lim:
                ev.margins[f"{k} at peak torque"] = lim[k].torque_nm / req.peak_torque_nm - 1.0
    if req.lost_motion_arcmin is not None:
        lo, hi = req.lost_motion_arcmin
        lm = None if sheet.lost_motion is None else 60.0 * math.degrees(sheet.lost_motion)
        ev.objectives["lost_motion"] = lm
        # inside [lo, hi]: the margin is the distance to the nearer end over the range's width
        ev.margins["lost motion"] = -1.0 if lm is None else min(lm - lo, hi - lm) / (hi - lo)
    fr = sheet.friction
    if fr is not None:
        ev.objectives["efficiency"] = float(fr.rated.efficiency())
    if req.min_efficiency is not None:
        eta = None if fr is None else float(fr.rated.efficiency())
        ev.margins["efficiency"] = -1.0 if eta is None else eta / req.min_efficiency - 1.0
    if req.entry_gap_closes_below_nm is not None:
        # an upper bound on a limit: the gap must close (tip interference at entry) below the torque given; a gap
        # still open where the model stopped ('above') is not shown to close at all: violated
        eg = lim["entry_gap"]
        ev.objectives["entry_gap_closes_nm"] = float(eg.torque_nm)
        ev.margins["entry gap closes below"] = -1.0 if eg.above else 1.0 - eg.torque_nm / req.entry_gap_closes_below_nm
    short = [k for k, v in ev.margins.items() if v is not None and v < 0]
    if short:
        ev.message = "rating: " + ", ".join(short)
        return False
    return True
