"""The clearance audit of an imperfect drive: every (generator angle, tooth, section) sample with its own pose, swept in chunks (docs/models.md 5, 6.2, 7).

Run-out, eccentricities and a cam offset tied to a gear or the housing
break the mesh period, the identical waves and the mirror symmetry
(:func:`wgcad.placement.imperfect.shortcuts`): every sample has its own pose.
What still saves work (docs/models.md 7, last paragraph):

* **the perfect twin**: a sample's clearance is at least the perfect
  drive's ``c(phi)`` at its tooth angle less how far the errors move its
  tooth against the rigid tooth it faces
  (:mod:`wgcad.clearance.imperfect_bounds`); ``c(phi)`` is bounded by the
  perfect engine's own culling and branch and bound, which the perfect
  drive's symmetries still serve, on a fixed grid of tooth angles;
* **lowest bounds first**: the samples with the lowest bounds anywhere set
  the bar; then only samples whose bound is below the running minimum are
  posed and measured, so nothing rests on a periodicity of the imperfect
  drive;
* **chunks**: the sweep is cut into blocks of generator angles; each block's
  bounds are dropped once it is done, and only the running minimum and the
  samples that can still hold it are kept, so the memory does not grow with
  the sweep length.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from math import pi

import numpy as np
import shapely

from ..placement import transform
from ..placement.imperfect import Imperfections, flex_poses_batch, full_cycle_turns, rigid_translation, shortcuts
from .cascade import FINE, refine_candidates
from .closing import closing_direct
from .engine import AuditResult, audit_run
from .entry import EDGES, edge_gaps, edge_index, entry_crossings, entry_pinch
from .findings import AuditRun, Finding, ImperfectRun
from .imperfect_bounds import ErrorBound, PerfectBound, PerfectBounds, chunk_bounds
from .imperfect_entry import imperfect_entry
from .imperfect_scene import ImperfectScene
from .scene import PairFigures, Scene, clearance_at_poses, refine_min

__all__ = [
    "ImperfectScene",
    "flex_poses_batch",
    "PerfectBound",
    "ErrorBound",
    "audit_imperfect",
    "chunk_angles",
    "CHUNK_SAMPLES",
]

#: samples (generator angles x teeth x sections) per chunk: a chunk's bounds and their temporaries
#: (~10 arrays of 8 bytes a sample) hold ~5 MB at 2**16, and the per-chunk overhead (a few array
#: passes) stays well below the evaluations' cost
CHUNK_SAMPLES = 1 << 16
#: polygons measured per call (as wgcad.clearance.search._CHUNK)
_BATCH = 4096
#: samples with the lowest bounds evaluated first, to set the bar for the sweep
_SEED = 256
#: candidates measured at once on the finer polygons (wgcad.clearance.cascade)
_FINE_BATCH = 256
#: candidates refined in one call (the 16 lowest first above that)
_ONE_CALL = 48


def chunk_angles(z_g: int, sections: int, chunk_samples: int = CHUNK_SAMPLES) -> int:
    """Generator angles per chunk for ``z_g`` teeth and ``sections`` sections."""
    return max(1, chunk_samples // (z_g * max(1, sections)))


def _evaluate_poses(scene, rot, shift) -> np.ndarray:
    vals = np.empty(len(rot))
    for a in range(0, len(rot), _BATCH):
        b = min(a + _BATCH, len(rot))
        vals[a:b] = clearance_at_poses(scene, rot[a:b], shift[a:b]).min
    return vals


def _classify(scene: Scene, rot: float, shift: np.ndarray, j: int) -> str:
    """Where on the flexspline tooth at pose ``(rot, shift)`` the closest approach to rigid tooth ``j`` lies.

    As :func:`wgcad.clearance.scene.classify`, from the pose itself (an
    imperfect tooth's pose is not a function of its tooth angle).
    """
    pts = transform(scene.flex_local, np.array([rot]), shift[None, :])[0]
    a = shapely.Polygon(pts)
    b = scene.rigid_geoms[j]
    if a.intersects(b):
        inter = a.intersection(b)
        p = np.asarray(inter.representative_point().coords[0]) if not inter.is_empty else pts[0]
    else:
        p = np.asarray(shapely.shortest_line(a, b).coords[0])
    c, s = np.cos(-rot), np.sin(-rot)
    q = p - shift
    loc = np.array([c * q[0] - s * q[1], s * q[0] + c * q[1]])  # tooth frame: the tooth centred on +x
    R = float(np.hypot(*loc))
    g = scene.drive.flex
    m = g.spec.module
    if abs(R - g.r_a) < 0.05 * m:
        return "tip"
    filleted = g.spec.form in ("involute", "double_arc")
    if (abs(R - g.r_f) < (g.spec.fillet_coef + 0.05) * m) if filleted else abs(R - g.r_f) < 0.05 * m:
        return "root"
    side = "upper" if loc[1] > 0 else "lower"
    return "working flank" if side == scene.working else "non-working flank"


def _poses_of(drive, imp, angles, a_idx, k_idx, s_idx, sections):
    """Poses of samples (angle index, tooth, section index) relative to the rigid gear's centre (:class:`ImperfectScene`), ``(K,)``, ``(K, 2)``."""
    rot = np.empty(len(a_idx))
    shift = np.empty((len(a_idx), 2))
    for si, z in enumerate(sections):
        sel = np.nonzero(s_idx == si)[0]
        if sel.size:
            rot[sel], shift[sel] = flex_poses_batch(drive, imp, angles[a_idx[sel]], k_idx[sel], [z])[0]
    return rot, shift - rigid_translation(imp)


def audit_imperfect(drive, settings, imp: Imperfections, progress=None, chunk_samples: int = CHUNK_SAMPLES):
    """Clearance audit of a drive with imperfect parts (module docstring): the smallest clearance and where.

    Parameters
    ----------
    drive : wgcad.drive.Drive
    settings : wgcad.clearance.search.AuditSettings
        ``angles``, ``sections``, ``cull``, ``bound``, ``refine`` and
        ``interference_tol`` are used; the mesh period, wave and mirror
        shortcuts do not hold with these errors and are not used.
    imp : Imperfections
    progress : callable, optional
        ``progress(done, total, stage)``.
    chunk_samples : int
        Samples per chunk (memory; the figures do not depend on it).

    Returns
    -------
    wgcad.clearance.engine.AuditResult
        Entry gap and pinch over every passage of a tooth through the entry
        (:mod:`wgcad.clearance.imperfect_entry`); the backlash is the
        imperfect drive's at the first generator angle.
    """
    t0 = time.perf_counter()
    run = _Run.make(drive, settings, imp, chunk_samples)
    if progress is not None:
        progress(300, 1000, "clearance")
    found = _search(run, progress)
    best_poly = float(found.best)
    best, where, n_refined, n_fine = _refine(run, found)
    if progress is not None:
        progress(900, 1000, "refine")
    worst = _worst_finding(run, found, where, best, best_poly)
    if progress is not None:
        progress(920, 1000, "entry gap")
    gaps, ent = _entry(run)
    # backlash of the imperfect drive at the first generator angle, middle section: the rigid turn of the
    # flexspline between contact either way, from the exact poses (wgcad.clearance.closing.closing_direct)
    z_mid = run.sections[len(run.sections) // 2]
    bl = _backlash(drive, imp, float(run.angles[0]), z_mid)
    if progress is not None:
        progress(1000, 1000, "done")
    A, S = len(run.angles), len(run.sections)
    counts = {
        "samples": int(A * run.z_g * S),
        "unique_tooth_angles": int(A * run.z_g),
        "sections": S,
        "evaluated": int(found.n_ev),
        "culled": int(found.n_pruned),
        "perfect_evaluated": found.perfect.evaluated,
        "refined": int(n_refined),
        "fine_polygon": int(n_fine),
        "chunks": -(-A // run.B),
    }
    gap_f, pinch_f, delta_f = _entry_findings(run, gaps, ent)
    findings = {
        "min_clearance": worst,
        "entry_gap": delta_f,
        "entry_crossing": gap_f,
        "entry_pinch": pinch_f,
        "backlash": Finding("backlash", float(bl), "brent", generator_angle=float(run.angles[0]), section_z=z_mid),
    }
    res = AuditResult(
        settings=_audit_run(run),
        findings=findings,
        interference=best < -settings.interference_tol,
        interference_tol=settings.interference_tol,
        counts=counts,
        settings_angles=run.angles,
    )
    res.elapsed_s = time.perf_counter() - t0
    return res


@dataclass(slots=True)
class _Run:
    """What every step of an imperfect audit shares: the drive and its errors, the scenes, the samples' axes."""

    drive: object
    settings: object
    imp: Imperfections
    scene: Scene
    isc: ImperfectScene
    angles: np.ndarray
    sections: list
    z_g: int
    B: int  # generator angles per chunk
    margin: float  # the polygon-curve margin of the candidates (0 without refinement)

    @classmethod
    def make(cls, drive, settings, imp, chunk_samples):
        scene = Scene(drive)
        angles = np.asarray(settings.angles, dtype=float)
        sections = [None] if not drive.coned else [float(z) for z in settings.sections]
        return cls(
            drive,
            settings,
            imp,
            scene,
            ImperfectScene.from_scene(scene, imp),
            angles,
            sections,
            scene.z_g,
            min(len(angles), chunk_angles(scene.z_g, len(sections), chunk_samples)),
            2.0 * scene.chord_gap if settings.refine else 0.0,
        )

    def poses(self, a_, k_, s_):
        return _poses_of(self.drive, self.imp, self.angles, a_, k_, s_, self.sections)


@dataclass(slots=True)
class _Found:
    """The polygon search's result: its best figure, the candidates within the margin of it, what it cost."""

    best: float
    v: np.ndarray
    a: np.ndarray
    k: np.ndarray
    s: np.ndarray
    n_ev: int
    n_pruned: int
    perfect: PerfectBounds


class _Keeper:
    """Evaluates samples in batches and keeps those within the margin of the best so far."""

    def __init__(self, run: _Run):
        self.run = run
        self.best = np.inf
        self.n_ev = 0
        self.keep = [[np.zeros(0)], [np.zeros(0, int)], [np.zeros(0, int)], [np.zeros(0, int)]]

    def __call__(self, sel_s, sel_k, sel_a):
        run, margin = self.run, self.run.margin
        kv, ka, kk, ks = self.keep
        for a in range(0, len(sel_s), _BATCH):
            s_, k_, a_ = sel_s[a : a + _BATCH], sel_k[a : a + _BATCH], sel_a[a : a + _BATCH]
            rot, shift = run.poses(a_, k_, s_)
            v = _evaluate_poses(run.isc, rot, shift)
            self.n_ev += len(v)
            self.best = min(self.best, float(v.min()))
            ok = v <= self.best + margin
            kv.append(v[ok]), ka.append(a_[ok]), kk.append(k_[ok]), ks.append(s_[ok])
        v = np.concatenate(kv)
        ok = v <= self.best + margin
        self.keep = [[x[ok]] for x in (v, np.concatenate(ka), np.concatenate(kk), np.concatenate(ks))]


def _search(run: _Run, progress) -> _Found:
    """Every sample that can hold the imperfect minimum on polygons (branch and bound on the perfect drive's
    bounds less the errors' reach, or every sample with ``settings.bound`` off)."""
    settings, angles, z_g, S, B = run.settings, run.angles, run.z_g, len(run.sections), run.B
    A = len(angles)
    margin = run.margin
    eb = ErrorBound(run.scene, run.imp, run.sections)
    # the widest the errors can move a tooth against its rigid teeth: the imperfect minimum is within
    # that of the perfect one, so the perfect bounds are needed up to twice that above it
    e_max = eb.largest(angles)
    # the perfect drive's bounds, first as far as a perfect audit needs them; then as far as the sweep
    # needs them: a grid point whose bound is above (imperfect best + margin + e_max) prunes every sample
    perfect = PerfectBounds(run.scene, run.sections, settings)
    perfect.extend(margin)
    pb = perfect.pb
    keeper = _Keeper(run)
    n_pruned = 0
    if not settings.bound:
        # the reference: every sample in every chunk
        for a0 in range(0, A, B):
            a1 = min(A, a0 + B)
            s_, k_, b_ = np.meshgrid(np.arange(S), np.arange(z_g), np.arange(a0, a1), indexing="ij")
            keeper(s_.ravel(), k_.ravel(), b_.ravel())
    else:
        # first pass: the few samples with the lowest bounds anywhere set the bar; second pass: every
        # sample whose bound is below it, chunk by chunk, lowest bounds first
        seed = []
        for a0 in range(0, A, B):
            a1 = min(A, a0 + B)
            L = chunk_bounds(pb, eb, angles, a0, a1, z_g, S).ravel()
            m = min(_SEED, L.size)
            idx = np.argpartition(L, m - 1)[:m].copy()  # a copy: the view would keep the chunk's whole array alive
            seed.append((L[idx], idx, a0, a1))
        allL = np.concatenate([x[0] for x in seed])
        top = np.argsort(allL, kind="stable")[:_SEED]
        sel = []
        at = 0
        for L, idx, a0, a1 in seed:
            mine = top[(top >= at) & (top < at + len(L))] - at
            s_, k_, b_ = np.unravel_index(idx[mine], (S, z_g, a1 - a0))
            sel.append((s_, k_, b_ + a0))
            at += len(L)
        keeper(*(np.concatenate(x) for x in zip(*sel)))
        # the seeds' best is the imperfect minimum's upper bound; it is within e_max of the perfect one
        perfect.extend(min(keeper.best + margin + e_max - perfect.best, 2.0 * e_max + margin))
        done = set(zip(*(np.concatenate(x).tolist() for x in zip(*sel))))
        for a0 in range(0, A, B):
            a1 = min(A, a0 + B)
            L = chunk_bounds(pb, eb, angles, a0, a1, z_g, S).ravel()
            idx = np.nonzero(L < keeper.best + margin)[0]
            n_pruned += L.size - idx.size
            idx = idx[np.argsort(L[idx], kind="stable")]
            s_, k_, b_ = np.unravel_index(idx, (S, z_g, a1 - a0))
            b_ = b_ + a0
            fresh = np.array(
                [(x, y, w) not in done for x, y, w in zip(s_.tolist(), k_.tolist(), b_.tolist())], dtype=bool
            )
            # re-checked against the bar as it falls: a batch is dropped once its bounds are above it
            s_, k_, b_, Lc = s_[fresh], k_[fresh], b_[fresh], L[idx][fresh]
            for a in range(0, len(s_), _BATCH):
                live = Lc[a : a + _BATCH] < keeper.best + margin
                if not live.any():
                    n_pruned += len(Lc) - a
                    break
                n_pruned += int((~live).sum())
                keeper(s_[a : a + _BATCH][live], k_[a : a + _BATCH][live], b_[a : a + _BATCH][live])
            if progress is not None:
                progress(300 + int(500 * a1 / A), 1000, "clearance")
    v, a_, k_, s_ = (x[0] for x in keeper.keep)
    return _Found(keeper.best, v, a_, k_, s_, keeper.n_ev, n_pruned, perfect)


def _refine(run: _Run, found: _Found) -> tuple[float, int, int, int]:
    """The candidates on the exact curves (wgcad.clearance.cascade): ``(best, where, n_refined, n_fine)``."""
    if not (run.settings.refine and len(found.v)):
        return found.best, int(np.argsort(found.v, kind="stable")[0]), 0, 0

    # the finer polygons' figure of every pair of every candidate: the exact refinement then takes only the pairs
    # within the finer margin of their sample's smallest (as the perfect drive's audit, engine._refine)
    finer, finer_gap = None, None

    def fine(idx, bar=None):
        nonlocal finer, finer_gap
        ref = ImperfectScene.from_scene(Scene(run.drive.sampled_at(run.drive.tol / FINE)), run.imp)
        rot, shift = run.poses(found.a[idx], found.k[idx], found.s[idx])
        finer = PairFigures.full(len(found.v))
        # in batches: a candidate on the finer polygons holds ~18 kB while measured, and their number
        # grows with the sampling density (2900 at 0.05 deg on D1 [S4])
        for a in range(0, len(rot), _FINE_BATCH):
            det = clearance_at_poses(ref, rot[a : a + _FINE_BATCH], shift[a : a + _FINE_BATCH])
            finer.put(idx[a : a + _FINE_BATCH], det)
        finer_gap = ref.chord_gap
        return finer.min[idx], finer_gap

    def exact(idx):
        rot, shift = run.poses(found.a[idx], found.k[idx], found.s[idx])
        if finer is None:
            return refine_min(run.isc, rot, shift, clearance_at_poses(run.isc, rot, shift)).min
        return refine_min(run.isc, rot, shift, finer.take(idx), gap=finer_gap).min

    return refine_candidates(found.v, run.isc.chord_gap, exact, fine=fine, one_call=_ONE_CALL)


def _worst_finding(run: _Run, found: _Found, where: int, best: float, best_poly: float) -> Finding:
    """The tightest sample as a ``min_clearance`` Finding: where it is, against which rigid tooth, its overlap area."""
    angles, scene, isc = run.angles, run.scene, run.isc
    ai, k, si = int(found.a[where]), int(found.k[where]), int(found.s[where])
    rot, shift = run.poses(np.array([ai]), np.array([k]), np.array([si]))
    det = clearance_at_poses(isc, rot, shift, area=True)
    side, j = det.nearest(0)
    area = det.overlap_area(side, 0)
    phi_tooth = float((2 * pi * k / run.z_g + angles[ai] / scene.ratios["u_hg"] - angles[ai] + pi) % (2 * pi) - pi)
    phi_major = float((phi_tooth + pi / scene.n_w) % (2 * pi / scene.n_w) - pi / scene.n_w)
    return Finding(
        "min_clearance",
        float(best),
        "exact" if run.settings.refine else "polygon",
        tooth_angle=phi_major,
        section_z=run.sections[si],
        location=_classify(isc, float(rot[0]), shift[0], j),
        generator_angle=float(angles[ai]),
        tooth=k,
        polygon_value=float(best_poly),
        details={
            "mirror": None,  # the errors break the mirror symmetry
            "sample_tooth_angle": phi_tooth,
            "rigid_tooth": j,
            "overlap_area": float(area),
        },
    )


def _entry(run: _Run):
    """Every passage of a tooth through the entry in the swept angles, each with its own crossing
    (wgcad.clearance.imperfect_entry), found from the perfect drive's (polygons suffice there: they only say
    where to look). Returns the perfect drive's crossings per section and the passages' figures."""
    scene, sections, angles = run.scene, run.sections, run.angles
    gaps = list(zip(entry_crossings(scene, sections, exact=False), sections))
    crossed = any(np.isfinite(g[0]) for g, _ in gaps)
    p_pinch = entry_pinch(scene, [(g[1], z) for g, z in gaps if np.isfinite(g[0])], exact=False) if crossed else None
    # with the cam-borne offset alone (or no errors) every passage of a section is congruent (the mesh period
    # holds, docs/models.md 7): one passage per section stands for all
    span = np.array([angles[0], angles[0] + 2 * pi / scene.z_b]) if shortcuts(run.imp)["mesh_period"] else angles
    if not crossed:
        return gaps, {}
    return gaps, imperfect_entry(run.drive, run.imp, run.isc, scene, gaps, p_pinch, span, sections, run.settings.refine)


def _audit_run(run: _Run) -> AuditRun:
    """What the audit ran with: no shortcut of the perfect drive, and how much of the error cycle it swept."""
    angles = run.angles
    A = len(angles)
    sc = shortcuts(run.imp)
    base = audit_run(run.drive, run.scene, run.settings, angles, run.sections)
    imp = ImperfectRun(
        generator_turns=float(
            (angles[-1] - angles[0]) / (2 * pi) + (np.median(np.diff(angles)) / (2 * pi) if A > 1 else 0.0)
        ),
        full_cycle_turns=int(full_cycle_turns(run.drive.design.drive.z_flex, run.drive.design.drive.z_rigid)),
        shortcuts_that_hold={
            k: sc[k] for k in ("mesh_period", "identical_waves", "mirror_symmetry", "one_generator_turn")
        },
        why=sc["why"],
        chunk=int(run.B),
    )
    return replace(base, mesh_period=False, identical_waves=False, mirror_symmetry=False, imperfect=imp)


def _entry_findings(run: _Run, gaps, ent: dict):
    """The entry crossing, the pinch and [S1]'s Delta of every passage as Findings."""
    drive, imp, isc, settings, scene = run.drive, run.imp, run.isc, run.settings, run.scene
    exact = "exact" if settings.refine else "polygon"
    fold = lambda a: float((a + pi / scene.n_w) % (2 * pi / scene.n_w) - pi / scene.n_w)  # noqa: E731  (nearest major axis)
    if np.isfinite(ent.get("gap", np.nan)):
        edge, gloc = _entry_edge(drive, imp, isc, ent["gap_phi_h"], ent["gap_tooth"], ent["gap_z"], settings.refine)
        gap_f = Finding(
            "entry_crossing",
            ent["gap"],
            exact,
            tooth_angle=fold(ent["gap_tooth_angle"]),
            section_z=ent["gap_z"],
            location=gloc,
            generator_angle=ent["gap_phi_h"],
            tooth=ent["gap_tooth"],
            details={
                "crossing": "flexspline tip arc crossing the rigid tip circle",
                "edge": edge,
                "passages": ent["passages"],
                "spread": ent["spread"],
                "all_passages": ent["all"],
                "perfect_gaps": [float(g[0]) for g, _ in gaps],
                "perfect_phi": [float(g[1]) for g, _ in gaps],
            },
        )
    else:
        gap_f = Finding("entry_crossing", float("nan"), exact, details={"passages": ent.get("passages", 0)})
    if np.isfinite(ent.get("pinch", np.nan)):
        ploc = _classify(isc, ent["pinch_rot"], ent["pinch_shift"], ent["pinch_rigid"])
        pedge = _entry_edge(
            drive,
            imp,
            isc,
            ent["pinch_phi_h"],
            ent["pinch_tooth"],
            ent["pinch_z"],
            settings.refine,
            rigid=ent["pinch_rigid"],
        )[0]
        pinch_f = Finding(
            "entry_pinch",
            ent["pinch"],
            exact,
            tooth_angle=fold(ent["pinch_tooth_angle"]),
            section_z=ent["pinch_z"],
            location=ploc,
            generator_angle=ent["pinch_phi_h"],
            tooth=ent["pinch_tooth"],
            details={
                "edge": pedge,
                "tip_to_tip_risk": bool(ent["pinch"] < settings.interference_tol and ploc == "tip"),
            },
        )
    else:
        pinch_f = Finding("entry_pinch", float("nan"), exact, details={"tip_to_tip_risk": False})
    # Delta of [S1] (docs/models.md 5): the smallest gap of the entry, the pinch where the tips pass or, without
    # one, the crossing; over every passage
    delta_src, kind = (
        (pinch_f, "pinch") if np.isfinite(pinch_f.value) and not (pinch_f.value > gap_f.value) else (gap_f, "crossing")
    )
    delta_f = Finding(
        "entry_gap",
        float(delta_src.value),
        exact,
        tooth_angle=delta_src.tooth_angle,
        section_z=delta_src.section_z,
        location=delta_src.location,
        generator_angle=delta_src.generator_angle,
        tooth=delta_src.tooth,
        details={
            "kind": kind if np.isfinite(delta_src.value) else None,
            "edge": delta_src.details.get("edge"),
            "tip_to_tip_risk": bool(pinch_f.details.get("tip_to_tip_risk", False) and kind == "pinch"),
        },
    )
    return gap_f, pinch_f, delta_f


def _entry_edge(drive, imp: Imperfections, isc: ImperfectScene, phi_h: float, k: int, z, exact: bool, rigid=None):
    """The edge (working / non-working) of the entry gap of tooth ``k`` at ``phi_h``, section ``z``, and where on
    the tooth it lies: the edge facing rigid tooth ``rigid`` or, without one, the edge with the smaller gap."""
    rot, shift = flex_poses_batch(drive, imp, np.array([phi_h]), np.array([k]), [z])[0]
    shift = isc.relative(shift)
    idx = edge_index(isc, rot, shift)
    if rigid is None:
        e = int(np.argmin(edge_gaps(isc, rot, shift, exact=exact)[0]))
    else:
        e = 0 if int(idx[0][0]) == int(rigid) else 1
    return EDGES[e], _classify(isc, float(rot[0]), shift[0], int(idx[e][0]))


def _backlash(drive, imp: Imperfections, phi_h: float, z) -> float:
    """Dead travel (rad) of the imperfect drive at ``phi_h``: closing rotations either way; NaN if the teeth interfere."""
    if drive.design.drive.fixed != "rigid":
        return float("nan")
    up = closing_direct(drive, imp, phi_h, 1, sections=[z])
    dn = closing_direct(drive, imp, phi_h, -1, sections=[z])
    tot = up + dn
    if not np.isfinite(tot):
        return float("inf")
    return float(tot) if tot >= 0 and up >= 0 and dn >= 0 else float("nan")
