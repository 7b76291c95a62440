"""The 2D clearance engine: every flexspline tooth against its nearest rigid teeth over generator angles and sections (docs/models.md 5, 7).

Why it can skip work (each switchable, each tested against the full computation):

* **mesh period** (docs/models.md 7): for perfect gears the state of a tooth
  depends only on its angle ``phi`` from the generator's major axis. A tooth
  at ``phi`` has its material angle at ``phi (z_b - z_g)/z_b`` modulo a rigid
  pitch, so every (generator angle, tooth) sample is a sample of one
  function ``c(phi)`` per section, and equal ``phi`` need one evaluation.
* **identical waves**: ``c`` is periodic in ``2 pi / n_w`` (the law is, and
  a wave shifts the rigid teeth by ``(z_b - z_g)/n_w`` whole pitches), so
  ``phi`` folds into one wave. With tooth counts that are multiples of
  ``n_w`` the folded samples coincide; with odd counts they interleave.
* **mirror symmetry**: teeth are symmetric and every deformation law is
  even in ``phi``, and a tooth at ``-phi`` sits at ``-phi (z_b - z_g)/z_b``
  against the rigid teeth: the scene at ``-phi`` is the mirror image of the
  one at ``phi``, so ``c(-phi) = c(phi)`` with the two flanks swapped.
* **culling**: a tooth whose outermost point is inside the rigid tip circle
  (internal deformation) is radially separated from all rigid material by
  at least the gap between the two radii; it is evaluated only if that
  bound is below the minimum found. The third-nearest rigid tooth is
  evaluated only where ``2 R sin(dphi/2)`` does not already exceed the
  clearance to the two bracketing teeth.
* **branch and bound**: ``c`` is Lipschitz in ``phi`` (a rigid motion moves
  the tooth by at most ``V dphi``, with ``V`` bounded from the law's
  derivatives, :meth:`Scene.speed_bound`), so a sample between two
  evaluated ones is bounded below by ``max(c_i - V |phi - phi_i|)``; only
  samples whose bound is below the running minimum are evaluated, on
  successively finer strides.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import pi

import numpy as np

from ..placement import tooth_pose
from .backlash import backlash
from .cascade import FINE, refine_candidates
from .entry import (
    EDGES,
    entry_crossings,
    entry_gap,
    entry_passages,
    entry_pinch,
    lipschitz_min,
    location,
    section_poses,
    smallest,
)
from .findings import AuditRun, Finding
from .scene import (
    PairFigures,
    Scene,
    classify,
    clearance_at_poses,
    refine_min,
    tooth_clearance,
    tooth_clearance_sections,
)
from .search import AuditSettings, SectionSearch, evaluate, fold, sample_phi

__all__ = [
    "AuditSettings",
    "AuditResult",
    "Finding",
    "Scene",
    "tooth_clearance",
    "clearance_at_poses",
    "clearance_profile",
    "clearance_vs_angle",
    "audit",
    "brute_force_min",
    "backlash",
    "entry_crossings",
    "entry_gap",
    "entry_pinch",
    "lipschitz_min",
    "refine_min",
    "tooth_clearance_sections",
]


@dataclass(slots=True)
class AuditResult:
    """Figures of an audit as :class:`~wgcad.clearance.findings.Finding` records (mm, rad inside).

    The report layer (:mod:`wgcad.report.audit`) shapes them for JSON and
    the printed summary; the properties below are the figures programs use
    most, read off the records.
    """

    settings: AuditRun
    findings: dict
    interference: bool
    interference_tol: float
    counts: dict
    settings_angles: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    elapsed_s: float = 0.0

    @property
    def min_clearance(self) -> float:
        return self.findings["min_clearance"].value

    @property
    def entry_gap(self) -> float:
        return self.findings["entry_gap"].value

    @property
    def backlash(self) -> float:
        return self.findings["backlash"].value

    @property
    def entry_side(self) -> str:
        return "entry (+phi)" if self.settings.entry_sign > 0 else "entry (-phi)"

    @property
    def raw(self) -> dict:
        """Unrounded tooth angles (rad) of the tightest spot, the entry crossing and the pinch."""
        f = self.findings
        return {
            "worst_phi": f["min_clearance"].tooth_angle,
            "entry_phi": f["entry_gap"].tooth_angle,
            "crossing_phi": f["entry_crossing"].tooth_angle if "entry_crossing" in f else None,
            "pinch_phi": f["entry_pinch"].tooth_angle,
            "min_clearance_polygon": f["min_clearance"].polygon_value,
        }


#: samples measured at once in the refinement stages: a flat minimum (D1's tip against a flank near the major axis
#: at the open end) leaves thousands of candidates at fine angle steps; in batches the memory stays bounded
#: (the fine polygons' pairs of 2048 samples take ~60 MB), the cost per batch is what one call costs
_BATCH = 2048


def _chunked(fn, n: int) -> np.ndarray:
    """``fn(slice)`` over ``range(n)`` in batches of :data:`_BATCH`, concatenated."""
    return np.concatenate([fn(slice(a, min(a + _BATCH, n))) for a in range(0, n, _BATCH)]) if n else np.zeros(0)


def _ticker(progress):
    """``tick(fraction, stage)`` -> ``progress(done, total, stage)`` in thousandths of the whole audit's work."""
    if progress is None:
        return lambda frac, stage: None
    return lambda frac, stage: progress(int(round(1000 * min(max(frac, 0.0), 1.0))), 1000, stage)


#: share of an audit's run time spent in each stage (measured on D1, full revolution, 3 sections):
#: the progress fractions follow the work, not the stage count
_STAGES = {
    "clearance": (0.0, 0.70),
    "refine": (0.70, 0.80),
    "entry gap": (0.80, 0.86),
    "pinch": (0.86, 0.95),
    "backlash": (0.95, 1.0),
}


def _stage(tick, name):
    a, b = _STAGES[name]
    return lambda f: tick(a + (b - a) * f, name)


def _canonical(scene: Scene, folded: np.ndarray, phi_w: float, z, exact: bool):
    """The worst spot folded to the nearest major axis: ``(phi >= 0, location, mirror location, sample index)``.

    Teeth and laws are symmetric: the tooth at ``-phi`` is the mirror image
    of the one at ``+phi`` with its flanks swapped, so both are named and
    the spot is reported at ``+|phi|`` whichever sample the search met
    first (so the printed spot does not depend on the shortcuts).
    The sample is the first (generator angle, tooth) in order whose tooth
    angle folds to ``+|phi|`` (else ``-|phi|``); ``folded`` holds every
    sample's tooth angle folded to the nearest major axis, ``(A, z_g)``.
    """
    a = abs(float(fold(np.array([phi_w]), 2 * pi / scene.n_w)[0]))
    folded = folded.ravel()
    hit = np.nonzero(np.abs(folded - a) <= 1e-9)[0]
    sgn = 1.0
    if hit.size == 0:
        hit = np.nonzero(np.abs(folded + a) <= 1e-9)[0]
        sgn = -1.0
    flat = int(hit[0]) if hit.size else int(np.argmin(np.abs(np.abs(folded) - a)))
    locs = []
    both = np.array([a, -a])
    det = tooth_clearance(scene, both, z, exact=exact)  # the spot and its mirror image in one call
    placed = scene.place(both, z)
    for i, p in enumerate(both):
        locs.append(classify(scene, placed[i], det.nearest(i)[1], float(p), z))
    return a, locs[0], locs[1], flat, sgn


def audit(drive, settings: AuditSettings, progress=None) -> AuditResult:
    """Clearance audit of a drive over generator angles and sections (2D engine, docs/models.md 5, 7).

    The polygons find the tightest samples (branch and bound with a margin
    for the polygon-curve difference); every sample that can be the
    minimum is then refined on the exact curves (``settings.refine``), and
    so are the entry gap and the pinch. ``progress``, if given, is called as
    ``progress(done, total, stage)`` with ``done/total`` the fraction of the
    audit's work done so far.
    """
    t0 = time.perf_counter()
    tick = _ticker(progress)
    scene = Scene(drive)
    angles = np.asarray(settings.angles, dtype=float)
    sections = [None] if not drive.coned else [float(z) for z in settings.sections]
    phi_all = sample_phi(scene, angles)  # (A, z_g)
    period = 2 * pi / scene.n_w if settings.use_waves else 2 * pi
    key = fold(phi_all, period)
    # every sample's tooth angle folded to the nearest major axis (where the worst spot is named)
    folded = key if settings.use_waves else fold(phi_all, 2 * pi / scene.n_w)
    if settings.use_mirror:
        key = np.abs(key)
    n_samples = phi_all.size * len(sections)
    if settings.use_period:
        phi_u = np.unique(np.round(key, 12))
    else:
        phi_u = key.ravel()
    order = np.argsort(phi_u, kind="stable")
    phi_sorted = phi_u[order]
    results, best_poly = _polygon_search(scene, phi_sorted, sections, settings, _stage(tick, "clearance"))
    # refinement on the exact curves of every sample that can hold the minimum
    stg = _stage(tick, "refine")
    stg(0.0)
    cands = _candidates(scene, results, best_poly, settings)
    best, where, n_refined, n_fine = _refine(drive, scene, phi_sorted, sections, cands, settings, best_poly, stg)
    si, i = where
    z_w = sections[si]
    worst = _worst_finding(scene, folded, float(phi_sorted[i]), z_w, settings.refine, angles, best, best_poly)
    ste = _stage(tick, "entry gap")
    ste(0.0)
    entry, crossing_f, pinch_f = entry_findings(scene, sections, settings.refine, settings.interference_tol)
    if np.isfinite(pinch_f.value) and pinch_f.value < best:
        # a pinch is a sample of the same clearance, found by its own finer search: the minimum holds it too
        best = float(pinch_f.value)
        worst = _worst_finding(
            scene,
            folded,
            float(pinch_f.tooth_angle),
            pinch_f.section_z,
            settings.refine,
            angles,
            best,
            best_poly,
        )
    _stage(tick, "backlash")(0.0)
    # backlash at the first requested generator angle, middle section
    z_mid = sections[len(sections) // 2]
    bl = float(backlash(scene, float(angles[0]), z_mid, exact=settings.refine))
    backlash_f = Finding(
        "backlash", bl, "exact" if settings.refine else "brent", generator_angle=float(angles[0]), section_z=z_mid
    )
    tick(1.0, "done")
    evaluated = int(sum(r.evaluated.sum() for r in results))
    counts = {
        "samples": int(n_samples),
        "unique_tooth_angles": int(len(phi_u)),
        "sections": len(sections),
        "evaluated": evaluated,
        "culled": int(sum(r.culled for r in results)),
        "refined": int(n_refined),
        "fine_polygon": int(n_fine),
    }
    res = AuditResult(
        settings=audit_run(drive, scene, settings, angles, sections),
        findings={
            "min_clearance": worst,
            "entry_gap": entry,
            "entry_crossing": crossing_f,
            "entry_pinch": pinch_f,
            "backlash": backlash_f,
        },
        interference=best < -settings.interference_tol,
        interference_tol=settings.interference_tol,
        counts=counts,
        settings_angles=angles,
    )
    res.elapsed_s = time.perf_counter() - t0
    return res


def _polygon_search(scene: Scene, phi_sorted: np.ndarray, sections: list, settings: AuditSettings, st):
    """Branch and bound on the polygons over every section: the sections' searches and the smallest figure."""
    results = [SectionSearch(scene, phi_sorted, z, settings) for z in sections]
    for r in results:
        r.prepare_bound()
    st(0.0)
    # coarse pass over every section first: the best of any prunes all; then finer strides
    best = evaluate(scene, results, [r.coarse() for r in results], sections, lambda f: st(0.3 * f))
    for step, stride in enumerate((64, 16, 4, 1)):
        best = evaluate(
            scene,
            results,
            [r.candidates(stride, best) for r in results],
            sections,
            lambda f, s=step: st(0.3 + 0.15 * (s + f)),
        )
    best = evaluate(scene, results, [r.culled_needed(best) for r in results], sections, lambda f: st(0.9 + 0.1 * f))
    return results, best


def _candidates(scene: Scene, results: list, best_poly: float, settings: AuditSettings):
    """Every evaluated sample within the polygon-curve margin of the polygon minimum: (section, sample, figure, and
    its pairs' figures (n, 3))."""
    cand_s, cand_i, cand_v, cand_p = [], [], [], []
    for si, r in enumerate(results):
        ev = np.nonzero(r.evaluated)[0]
        lim = best_poly + (2.0 * scene.chord_gap if settings.refine else 0.0)
        keep = ev[r.value[ev] <= lim]
        cand_s.append(np.full(keep.size, si))
        cand_i.append(keep)
        cand_v.append(r.value[keep])
        cand_p.append(r.pairs[keep])
    return np.concatenate(cand_s), np.concatenate(cand_i), np.concatenate(cand_v), np.concatenate(cand_p)


def _refine(drive, scene: Scene, phi_sorted, sections, cands, settings: AuditSettings, best_poly: float, stg):
    """The minimum on the exact curves (wgcad.clearance.cascade) and the (section, sample) holding it."""
    cand_s, cand_i, cand_v, cand_pairs = cands
    best = best_poly
    n_refined = n_fine = 0
    if settings.refine:
        # the finer polygons' figure of every pair of every candidate, once they have been measured: the exact
        # refinement then takes only the pairs within the finer margin of their sample's smallest (the pair that
        # holds a sample's exact minimum is among them), about half the pairs of a flat minimum
        finer, finer_gap = None, None

        def fine(idx, bar=np.inf):
            # many samples within the polygon-curve margin (a flat minimum): polygons FINE times finer
            nonlocal finer, finer_gap
            ref_scene = Scene(drive.sampled_at(drive.tol / FINE))
            finer = PairFigures.full(len(cand_v))

            def part(sl):
                k = idx[sl]
                rot, shift = ref_scene.pose_sections(phi_sorted[cand_i[k]], cand_s[k], sections)
                # only the pairs whose polygon figure can hold their sample's minimum (within twice the
                # polygon-curve gap of it: as scene.refine_min): about half of them
                coarse = cand_pairs[k]
                need = coarse <= np.nanmin(coarse, axis=1, keepdims=True) + 2.0 * scene.chord_gap
                need &= coarse - scene.chord_gap < bar  # nor those that cannot go below the exact figures' best
                det = clearance_at_poses(ref_scene, rot, shift, need=need)
                finer.put(k, det)
                return det.min

            vals = _chunked(part, len(idx))
            finer_gap = ref_scene.chord_gap
            return vals, finer_gap

        def exact(idx):
            def part(c):
                k = idx[c]
                if finer is None:
                    return tooth_clearance_sections(scene, phi_sorted[cand_i[k]], cand_s[k], sections, exact=True)
                rot, shift = scene.pose_sections(phi_sorted[cand_i[k]], cand_s[k], sections)
                return refine_min(scene, rot, shift, finer.take(k), gap=finer_gap).min

            return _chunked(part, len(idx))

        best, w, n_refined, n_fine = refine_candidates(cand_v, scene.chord_gap, exact, fine=fine, progress=stg)
        where = (int(cand_s[w]), int(cand_i[w]))
    else:
        w = int(np.argsort(cand_v, kind="stable")[0])
        where = (int(cand_s[w]), int(cand_i[w]))
    return best, where, n_refined, n_fine


def audit_run(drive, scene: Scene, settings: AuditSettings, angles: np.ndarray, sections: list) -> AuditRun:
    """What a perfect drive's audit ran with."""
    return AuditRun(
        angles=np.asarray(angles, dtype=float),
        sections=tuple(sections),
        coned=bool(drive.coned),
        face_width=float(drive.design.drive.face_width),
        mesh_period=bool(settings.use_period),
        identical_waves=bool(settings.use_waves),
        mirror_symmetry=bool(settings.use_mirror),
        culling=bool(settings.cull),
        branch_and_bound=bool(settings.bound),
        refined=bool(settings.refine),
        chord_tol=float(drive.tol),
        working_flank=scene.working,
        entry_sign=1 if scene.entry_sign > 0 else -1,
        rigid_pitch_radius=float(drive.rigid.r),
    )


def entry_findings(scene: Scene, sections: list, refine: bool, interference_tol: float):
    """Delta of [S1] (``entry_gap``), the crossing (``entry_crossing``) and the smallest pinch (``entry_pinch``) of the
    analytic law over the sections, as :class:`Finding` records (docs/models.md 5)."""
    method = "exact" if refine else "polygon"
    passages = entry_passages(scene, section_poses(scene, sections), len(sections), exact=refine)
    nan = float("nan")
    best = smallest(passages)
    if best is None:  # the tips never cross the rigid tip circle
        return (
            Finding("entry_gap", nan, method),
            Finding("entry_crossing", nan, method),
            Finding("entry_pinch", nan, method, details={"tip_to_tip_risk": False}),
        )
    z = sections[best.index]
    e = EDGES.index(best.delta_edge)
    loc = location(scene, best.delta_phi, z, e)
    per = [
        {
            "section_z": sections[p.index],
            "crossing": p.crossing,
            "crossing_gaps": p.crossing_gaps,
            "pinch": p.pinch,
            "delta": p.delta,
            "delta_phi": p.delta_phi,
            "edge": p.delta_edge,
            "kind": p.delta_kind,
        }
        for p in passages
    ]
    gap = Finding(
        "entry_gap",
        best.delta,
        method,
        tooth_angle=best.delta_phi,
        section_z=z,
        location=loc,
        details={
            "edge": best.delta_edge,
            "kind": best.delta_kind,
            "passages": per,
            "tip_to_tip_risk": bool(best.delta < interference_tol and loc == "tip"),
        },
    )
    cr = min((p for p in passages if np.isfinite(p.crossing)), key=lambda p: min(p.crossing_gaps))
    ce = int(np.argmin(cr.crossing_gaps))
    crossing = Finding(
        "entry_crossing",
        float(cr.crossing_gaps[ce]),
        method,
        tooth_angle=cr.crossing,
        section_z=sections[cr.index],
        details={"edge": EDGES[ce], "crossing": "flexspline tip arc crossing the rigid tip circle"},
    )
    pins = [(pin[0], pin[1], p.index, e2) for p in passages for e2, pin in enumerate(p.pinch) if pin is not None]
    if pins:
        pv, pp, pk, pe = min(pins)
        ploc = location(scene, pp, sections[pk], pe)
        pinch = Finding(
            "entry_pinch",
            float(pv),
            method,
            tooth_angle=float(pp),
            section_z=sections[pk],
            location=ploc,
            details={"edge": EDGES[pe], "tip_to_tip_risk": bool(pv < interference_tol and ploc == "tip")},
        )
    else:
        pinch = Finding("entry_pinch", nan, method, details={"tip_to_tip_risk": False})
    return gap, crossing, pinch


def _worst_finding(
    scene: Scene, folded, phi_w: float, z_w, exact: bool, angles, best: float, best_poly: float
) -> Finding:
    """The smallest clearance as a :class:`Finding`: its canonical spot, the mirror image, the overlap area."""
    phi_c, loc, mirror_loc, flat, sgn_c = _canonical(scene, folded, phi_w, z_w, exact)
    ai, k = divmod(flat, scene.z_g)
    phi_rep = sgn_c * phi_c
    detail = tooth_clearance(scene, np.array([phi_rep]), z_w, area=True)
    area = detail.overlap_area(detail.nearest(0)[0], 0)
    return Finding(
        "min_clearance",
        float(best),
        "exact" if exact else "polygon",
        tooth_angle=float(phi_c),
        section_z=z_w,
        location=loc,
        generator_angle=float(angles[ai]),
        tooth=int(k),
        polygon_value=float(best_poly),
        details={
            "mirror": (float(-phi_c), mirror_loc),
            "sample_tooth_angle": float(phi_rep),
            "overlap_area": float(area),
        },
    )


def brute_force_min(drive, angles: np.ndarray, sections) -> float:
    """Reference: every flexspline tooth against its 3 nearest rigid teeth at every angle and section, no skips."""
    scene = Scene(drive)
    best = np.inf
    secs = [None] if not drive.coned else list(sections)
    for z in secs:
        law = scene.law(z)
        for phi_h in np.asarray(angles, dtype=float):
            k = np.arange(scene.z_g)
            mat = 2 * pi * k / scene.z_g + phi_h / scene.ratios["u_hg"]
            rot, shift = tooth_pose(law, mat - phi_h, drive.r_m, frame_angle=phi_h)
            lo, up, th = scene.neighbours(shift, rot)
            for idx in (lo, up, th):
                best = min(best, float(scene.clearance_to(rot, shift, idx).min()))
    return best


def clearance_profile(scene: Scene, sections, step_deg: float = 0.1) -> dict:
    """Per-tooth clearance against the tooth's angle from the major axis over one wave, per flank and section.

    This is the function ``c(phi)`` every tooth follows (perfect gears,
    docs/models.md 7): the picture designers reason with. Working flank: the
    side facing the rigid tooth that carries the load (:attr:`Scene.working`).

    Returns
    -------
    dict with ``phi`` (P,) rad and ``sections``: list of
    ``{"z", "working", "nonworking"}`` arrays (mm).
    """
    half = pi / scene.n_w
    phi = np.linspace(-half, half, int(round(2 * np.rad2deg(half) / step_deg)) + 1)
    out = []
    for z in sections:
        res = tooth_clearance(scene, phi, z, third=False)
        w, n = (res.upper, res.lower) if scene.working == "upper" else (res.lower, res.upper)
        out.append({"z": z, "working": w, "nonworking": n})
    return {"phi": phi, "sections": out}


def clearance_vs_angle(scene: Scene, profile: dict, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smallest clearance over the teeth at each generator angle, per flank (mm), read off the profile.

    Each tooth's clearance at a generator angle is the profile at its tooth
    angle (mesh period), linearly interpolated between profile points: a
    picture, not an exact figure (the audit's minimum is exact).
    """
    phi = fold(sample_phi(scene, np.asarray(angles, dtype=float)), 2 * pi / scene.n_w)
    w = np.full(len(angles), np.inf)
    n = np.full(len(angles), np.inf)
    for sec in profile["sections"]:
        w = np.minimum(w, np.interp(phi, profile["phi"], sec["working"]).min(axis=1))
        n = np.minimum(n, np.interp(phi, profile["phi"], sec["nonworking"]).min(axis=1))
    return w, n
