"""Variable heights of the coupling-sector teeth: the closed form of docs/models.md 2.3 and the same heights found by a clearance sweep."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..profiles.sector import MIN_HEIGHT_COEF, SectorLayout, TeethByHeight
from .motion import motion_law
from .scene import DEFAULT_CULL, DEFAULT_STEP_DEG, SectoredScene, facing_flex_tooth, sweep_angles

__all__ = [
    "ClosedFormHeights",
    "SimulatedHeights",
    "closed_form_heights",
    "simulated_heights",
    "assigned_angles",
    "register_angles",
    "listed_heights",
]


@dataclass(frozen=True, slots=True)
class ClosedFormHeights:
    """Heights by ``h_i = r_fix - (r_cr + w(phi_i) + h_s)``, at most the full height (docs/models.md 2.3, [S5]).

    Attributes
    ----------
    heights : (N,) float
        Every rigid tooth's height, mm (full where no flexspline tip faces it).
    phi_h : (N,) float
        Generator angle assigned to each tooth: the major axis on the sector
        boundary nearest the tooth, rad (NaN for transmission teeth).
    phi : (N,) float
        The tooth's angle from the major axis at that generator angle, rad.
    w : (N,) float
        ``w(phi)``, mm.
    r_fix, r_cr, h_s, w0, beta, full : float
        Rigid root radius, undeformed neutral-line radius, neutral line to
        flexspline tip, W0 (mm), wrap half-angle (rad, NaN if the law has
        none), full tooth height (mm).
    rule : str
        How the generator angle is chosen, in words.
    partner : (N,) int
        The flexspline tooth that faces each tooth at its generator angle: whose centre line stands nearest it
        (-1: none).
    partner_phi : (N,) float
        That flexspline tooth's own angle from the major axis, rad (``phi`` is the tooth's, where ``w`` is taken).
    formula : (N,) float
        The formula's height before the cap at the full height, mm (NaN where no angle is assigned).
    """

    heights: np.ndarray
    phi_h: np.ndarray
    phi: np.ndarray
    w: np.ndarray
    r_fix: float
    r_cr: float
    h_s: float
    w0: float
    beta: float
    full: float
    rule: str
    elapsed_s: float = 0.0
    iterations: int = 0
    partner: np.ndarray = field(default=None, repr=False)
    formula: np.ndarray = field(default=None, repr=False)
    partner_phi: np.ndarray = field(default=None, repr=False)


def assigned_angles(layout: SectorLayout) -> tuple[np.ndarray, np.ndarray]:
    """``assign = "boundary"``: the major axis on the sector boundary nearest each coupling tooth; the tooth's angle from the axis then.

    While the major axis is in a coupling sector the flexspline is taken to
    stand in register with its teeth, out of register only while the axis
    crosses a transmission sector. A coupling tooth is then at least its
    distance ``delta`` to the nearer boundary away from the axis, and ``w``
    falls monotonically from the major axis (every two-wave law of docs/models.md
    3 does), so the axis on the boundary is the worst case: ``phi_i = delta_i``.
    It ignores the wave's own tangential displacement ``v`` inside the
    coupling sector (see :func:`register_angles`).
    """
    lay = layout
    start = lay.bounds[lay.sector]
    end = lay.bounds[lay.sector + 1]
    near_start = (lay.centres - start) <= (end - lay.centres)
    phi_h = np.where(near_start, start, end)
    phi_h = np.where(lay.coupling, phi_h, np.nan)
    phi = np.where(lay.coupling, lay.delta, np.nan)
    return phi_h, phi


def register_angles(scene: SectoredScene, step_deg: float = DEFAULT_STEP_DEG, cull: float = DEFAULT_CULL):
    """``assign = "register"``: per coupling tooth, the generator angle of the sweep where a flexspline tip faces its tip land
    (out of register: the two tip lands overlap in angle) closest to the major axis; the flexspline tooth's angle from the axis then.

    Uses only the motion law and the tooth poses of docs/models.md 3.1 (no
    distances): a flexspline tooth is out of register with a coupling tooth
    while the axis crosses a transmission sector (the flexspline moves) and,
    inside a coupling sector, where the wave's tangential displacement
    ``v + h theta`` has shifted it by more than the gap between the tip
    lands. The largest ``w`` among those samples is at the smallest ``|phi|``.

    Returns
    -------
    phi_h, phi : (N,) float
        Generator angle and the facing tooth's angle from the axis, rad (NaN:
        no flexspline tip ever faces the tooth). Every tooth is examined:
        the teeth of a transmission sector next to a joint can be out of
        register too.
    flex : (N,) int
        The facing flexspline tooth (-1: none).
    """
    lay = scene.layout
    pairs = scene.pairs(sweep_angles(step_deg), cull)
    face = scene.facing(pairs)
    phi_h = np.full(lay.n_teeth, np.nan)
    phi = np.full(lay.n_teeth, np.nan)
    flex = np.full(lay.n_teeth, -1)
    ap = np.abs(pairs.phi)
    for i in np.unique(pairs.rigid[face]):
        mine = np.nonzero(face & (pairs.rigid == i))[0]
        if mine.size:
            j = mine[np.argmin(ap[mine])]
            phi_h[i] = pairs.phi_h[pairs.angle[j]]
            phi[i] = pairs.phi[j]
            flex[i] = pairs.flex[j]
    return phi_h, phi, flex


def closed_form_heights(
    drive, layout: SectorLayout, teeth: TeethByHeight, assign: str = "register", step_deg: float = DEFAULT_STEP_DEG
) -> ClosedFormHeights:
    """The closed-form heights of docs/models.md 2.3 with every parameter explicit.

    ``assign`` chooses the generator angle of each tooth: ``"register"``
    (:func:`register_angles`) or ``"boundary"`` (:func:`assigned_angles`).
    """
    t0 = time.perf_counter()
    fl = drive.flex
    r_fix = float(teeth.full.r_f)
    r_cr = float(drive.r_m)
    h_s = float(fl.r_a - drive.r_m)
    H = teeth.height
    h = np.full(layout.n_teeth, H)

    def formula(phi):
        w = np.full(layout.n_teeth, np.nan)
        ok = np.isfinite(phi)
        w[ok] = drive.law.state(phi[ok]).w
        raw = np.full(layout.n_teeth, np.nan)
        # docs/models.md 2.3: h_i = r_fix - r_ari, r_ari = r_cr + w(phi_h) + h_s; never above the full height
        raw[ok] = r_fix - (r_cr + w[ok] + h_s)
        out = np.full(layout.n_teeth, H)
        out[ok] = np.minimum(H, raw[ok])
        return out, w, raw

    if assign == "boundary":
        phi_h, phi = assigned_angles(layout)
        h, w, raw = formula(phi)
        rule = "major axis on the sector boundary nearest the tooth (phi_i = the tooth's distance to it)"
        iterations = 0
        partner = np.full(layout.n_teeth, -1)
        partner_phi = np.full(layout.n_teeth, np.nan)
        motion = motion_law(layout, drive.design.drive.z_flex)
        for b in np.unique(phi_h[np.isfinite(phi_h)]):
            sel = np.nonzero(phi_h == b)[0]
            partner[sel], partner_phi[sel] = facing_flex_tooth(
                drive.law, drive.r_m, motion, drive.design.drive.z_flex, b, layout.centres[sel]
            )
    elif assign == "register":
        phi_h, phi, partner = register_angles(SectoredScene(drive, layout, teeth, h), step_deg)
        partner_phi = phi
        h, w, raw = formula(phi)
        iterations = 1
        rule = (
            f"smallest |phi| (from the nearer wave end) over a {step_deg:g} deg sweep of half a turn with the motion "
            "law at which a flexspline tip land faces the tooth's tip land (out of register)"
        )
    else:
        raise ValueError(f"assign must be 'register' or 'boundary', got {assign!r}")
    g = drive.design.generator
    beta = float(np.deg2rad(g.beta_deg)) if g.beta_deg is not None else float("nan")
    for a in (h, phi_h, phi, w, partner, raw, partner_phi):
        a.setflags(write=False)
    return ClosedFormHeights(
        h,
        phi_h,
        phi,
        w,
        r_fix,
        r_cr,
        h_s,
        float(drive.law.w0),
        beta,
        H,
        rule,
        time.perf_counter() - t0,
        iterations,
        partner,
        raw,
        partner_phi,
    )


@dataclass(frozen=True, slots=True)
class SimulatedHeights:
    """Heights found by sweeping the generator (largest that keeps ``tip_clearance`` where tips face).

    Attributes
    ----------
    heights : (N,) float
        Every rigid tooth's height, mm (full where no flexspline tip faces it).
    tip_clearance : float
        The clearance kept, mm.
    worst_phi_h : (N,) float
        Generator angle of the sample that limits each tooth (NaN: full height), rad.
    worst_phi : (N,) float
        The flexspline tooth's angle from the major axis there, rad.
    unreachable : (N,) bool
        Even the lowest tooth (``MIN_HEIGHT_COEF`` m) misses the clearance.
    worst_flex : (N,) int
        The flexspline tooth of the sample that limits each tooth (-1: full height).
    """

    heights: np.ndarray
    tip_clearance: float
    worst_phi_h: np.ndarray
    worst_phi: np.ndarray
    unreachable: np.ndarray
    step_deg: float
    tol: float
    counts: dict = field(default_factory=dict)
    elapsed_s: float = 0.0
    worst_flex: np.ndarray = field(default=None, repr=False)


def _bisect_heights(pairs, lo: dict, hi: dict, violations, tip_clearance: float, tol: float) -> None:
    """Bisect every tooth's height between ``lo`` and ``hi`` (updated in place) to ``tol``: the largest that keeps
    ``tip_clearance`` to all its facing pairs (``violations(trial heights, pair indices)``, their clearances).

    A pair whose clearance at the trial height is at least tip_clearance plus the rest of the interval can no longer
    decide anything: moving the tip by dh changes the clearance by at most dh (the shorter tooth lies inside the
    taller), so it is dropped."""
    alive = np.isin(pairs.rigid, list(lo))
    while True:
        todo = [i for i in lo if hi[i] - lo[i] > tol]
        if not todo:
            break
        mid = {i: 0.5 * (lo[i] + hi[i]) for i in todo}
        sel = np.nonzero(alive & np.isin(pairs.rigid, todo))[0]
        c = violations(mid, sel)
        owner = pairs.rigid[sel]
        for i in todo:
            mine = owner == i
            ok = not mine.any() or c[mine].min() >= tip_clearance
            if ok:
                lo[i] = mid[i]
                slack = hi[i] - mid[i]
            else:
                hi[i] = mid[i]
                slack = 0.0
            alive[sel[mine & (c >= tip_clearance + slack)]] = False


def simulated_heights(
    drive,
    layout: SectorLayout,
    teeth: TeethByHeight,
    tip_clearance: float,
    step_deg: float = DEFAULT_STEP_DEG,
    tol: float = 1e-4,
    cull: float = DEFAULT_CULL,
) -> SimulatedHeights:
    """Largest height of every rigid tooth (coupling teeth, and any transmission tooth found at risk) that keeps
    ``tip_clearance`` (mm) to the flexspline tips that face it.

    The generator sweeps half a turn (identical waves; module docstring of
    :mod:`wgcad.sector.scene`) in ``step_deg`` steps with the motion law.
    The pairs that constrain a tooth are those whose flexspline tip land
    faces the tooth's tip land (out of register, :meth:`SectoredScene.facing`)
    and come closer than ``tip_clearance``; lowering the tooth (a tip-radius override, same flanks)
    only removes material, so each pair's clearance is non-increasing in the
    height and the largest admissible height is found by bisection to
    ``tol`` (mm), every tooth on its own (no symmetry assumed).
    """
    t0 = time.perf_counter()
    H = teeth.height
    N = layout.n_teeth
    h_min = MIN_HEIGHT_COEF * teeth.base.module
    scene = SectoredScene(drive, layout, teeth, np.full(N, H))
    pairs = scene.pairs(sweep_angles(step_deg), cull)
    n_all = len(pairs)

    pairs = pairs.take(scene.facing(pairs))
    heights = np.full(N, H)
    worst_phi_h = np.full(N, np.nan)
    worst_phi = np.full(N, np.nan)
    worst_flex = np.full(N, -1)
    unreachable = np.zeros(N, dtype=bool)
    evals = 0

    def violations(trial: dict, members: np.ndarray):
        """Clearance of the (facing) pairs ``members`` against their tooth at its trial height."""
        nonlocal evals
        sub = pairs.take(members)
        hs = np.array([trial[int(i)] for i in sub.rigid])
        evals += len(members)
        return scene.clearance(sub, heights=hs)

    teeth_all = [int(i) for i in np.unique(pairs.rigid)]
    members = np.arange(len(pairs))
    c_full = violations({i: H for i in teeth_all}, members)
    bad = [i for i in teeth_all if c_full[pairs.rigid == i].min() < tip_clearance]
    c_low = violations({i: h_min for i in bad}, np.nonzero(np.isin(pairs.rigid, bad))[0]) if bad else np.zeros(0)
    idx_bad = np.nonzero(np.isin(pairs.rigid, bad))[0]
    for i in bad:
        if c_low[pairs.rigid[idx_bad] == i].min() < tip_clearance:
            unreachable[i] = True
    lo = {i: h_min for i in bad if not unreachable[i]}
    hi = {i: H for i in bad if not unreachable[i]}
    _bisect_heights(pairs, lo, hi, violations, tip_clearance, tol)
    for i in bad:
        heights[i] = lo[i] if not unreachable[i] else h_min
    # where each lowered tooth is limited: its closest facing sample at the height found
    if bad:
        idx = np.nonzero(np.isin(pairs.rigid, bad))[0]
        c_end = violations({i: heights[i] for i in bad}, idx)
        for i in bad:
            mine = pairs.rigid[idx] == i
            j = idx[mine][np.argmin(c_end[mine])]
            worst_phi_h[i] = pairs.phi_h[pairs.angle[j]]
            worst_phi[i] = pairs.phi[j]
            worst_flex[i] = pairs.flex[j]
    teeth_at_risk = bad
    for a in (heights, worst_phi_h, worst_phi, unreachable, worst_flex):
        a.setflags(write=False)
    return SimulatedHeights(
        heights,
        tip_clearance,
        worst_phi_h,
        worst_phi,
        unreachable,
        step_deg,
        tol,
        {
            "pairs_swept": int(n_all),
            "pairs_at_risk": int(len(pairs)),
            "pair_evaluations": int(evals),
            "teeth_lowered": int(len(teeth_at_risk)),
        },
        time.perf_counter() - t0,
        worst_flex,
    )


def listed_heights(layout: SectorLayout, heights_mm, full: float) -> np.ndarray:
    """Every tooth's height from ``[sectors] heights_mm`` (one coupling sector's teeth, repeated in each), transmission teeth full.

    Raises
    ------
    DesignError
        A listed height above the full tooth height.
    """
    from ..errors import DesignError

    hm = np.asarray(heights_mm, dtype=float)
    for i, h in enumerate(hm):
        if h > full + 1e-12:
            raise DesignError(
                f"sectors.heights_mm[{i}]", f"{h:g} mm exceeds the full tooth height {full:.4f} mm (rigid root to tip)"
            )
    out = np.full(layout.n_teeth, full)
    out[layout.coupling] = hm[layout.index[layout.coupling]]
    out.setflags(write=False)
    return out
