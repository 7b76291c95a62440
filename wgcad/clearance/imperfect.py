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
from math import pi

import numpy as np
import shapely

from ..placement import transform
from ..placement.imperfect import Imperfections, flex_poses_batch, full_cycle_turns, rigid_translation, shortcuts
from .imperfect_bounds import ErrorBound, PerfectBound, PerfectBounds, chunk_bounds
from .imperfect_scene import ImperfectScene
from .scene import Scene, clearance_at_poses, refine_min

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
#: candidates above this many are first sorted out on polygons 8 times finer (as the engine does)
_FINE_ABOVE = 48
_FINE = 8
#: candidates measured at once on the finer polygons
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
        vals[a:b] = clearance_at_poses(scene, rot[a:b], shift[a:b])["min"]
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
    if (abs(R - g.r_f) < (g.spec.fillet_coef + 0.05) * m) if g.spec.form == "involute" else abs(R - g.r_f) < 0.05 * m:
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
    from .engine import AuditResult, accuracy_settings
    from .findings import Finding

    t0 = time.perf_counter()
    scene = Scene(drive)
    isc = ImperfectScene.from_scene(scene, imp)
    angles = np.asarray(settings.angles, dtype=float)
    sections = [None] if not drive.coned else [float(z) for z in settings.sections]
    z_g = scene.z_g
    S = len(sections)
    margin = 2.0 * scene.chord_gap if settings.refine else 0.0
    B = min(len(angles), chunk_angles(z_g, S, chunk_samples))
    A = len(angles)
    eb = ErrorBound(scene, imp, sections)
    # the widest the errors can move a tooth against its rigid teeth: the imperfect minimum is within
    # that of the perfect one, so the perfect bounds are needed up to twice that above it
    e_max = eb.largest(angles)
    # the perfect drive's bounds, first as far as a perfect audit needs them; then as far as the sweep
    # needs them: a grid point whose bound is above (imperfect best + margin + e_max) prunes every sample
    perfect = PerfectBounds(scene, sections, settings)
    perfect.extend(margin)
    pb = perfect.pb
    if progress is not None:
        progress(300, 1000, "clearance")
    best = np.inf
    n_ev = n_pruned = 0
    keep_v, keep_a, keep_k, keep_s = [np.zeros(0)], [np.zeros(0, int)], [np.zeros(0, int)], [np.zeros(0, int)]

    def run(sel_s, sel_k, sel_a):
        """Evaluate samples (in the order given, in batches), keep those within the margin; returns the best."""
        nonlocal best, n_ev, keep_v, keep_a, keep_k, keep_s
        for a in range(0, len(sel_s), _BATCH):
            s_, k_, a_ = sel_s[a : a + _BATCH], sel_k[a : a + _BATCH], sel_a[a : a + _BATCH]
            rot, shift = _poses_of(drive, imp, angles, a_, k_, s_, sections)
            v = _evaluate_poses(isc, rot, shift)
            n_ev += len(v)
            best = min(best, float(v.min()))
            ok = v <= best + margin
            keep_v.append(v[ok]), keep_a.append(a_[ok]), keep_k.append(k_[ok]), keep_s.append(s_[ok])
        v = np.concatenate(keep_v)
        ok = v <= best + margin
        keep_v, keep_a, keep_k, keep_s = (
            [x[ok]] for x in (v, np.concatenate(keep_a), np.concatenate(keep_k), np.concatenate(keep_s))
        )

    if not settings.bound:
        # the reference: every sample in every chunk
        for a0 in range(0, A, B):
            a1 = min(A, a0 + B)
            s_, k_, b_ = np.meshgrid(np.arange(S), np.arange(z_g), np.arange(a0, a1), indexing="ij")
            run(s_.ravel(), k_.ravel(), b_.ravel())
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
        run(*(np.concatenate(x) for x in zip(*sel)))
        # the seeds' best is the imperfect minimum's upper bound; it is within e_max of the perfect one
        perfect.extend(min(best + margin + e_max - perfect.best, 2.0 * e_max + margin))
        done = set(zip(*(np.concatenate(x).tolist() for x in zip(*sel))))
        for a0 in range(0, A, B):
            a1 = min(A, a0 + B)
            L = chunk_bounds(pb, eb, angles, a0, a1, z_g, S).ravel()
            idx = np.nonzero(L < best + margin)[0]
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
                live = Lc[a : a + _BATCH] < best + margin
                if not live.any():
                    n_pruned += len(Lc) - a
                    break
                n_pruned += int((~live).sum())
                run(s_[a : a + _BATCH][live], k_[a : a + _BATCH][live], b_[a : a + _BATCH][live])
            if progress is not None:
                progress(300 + int(500 * a1 / A), 1000, "clearance")
    cand_v, cand_a, cand_k, cand_s = keep_v[0], keep_a[0], keep_k[0], keep_s[0]
    o = np.argsort(cand_v, kind="stable")
    cand_v, cand_a, cand_k, cand_s = cand_v[o], cand_a[o], cand_k[o], cand_s[o]
    best_poly = float(best)
    n_refined = n_fine = 0
    where = 0
    if settings.refine and len(cand_v):
        ref = isc
        if len(cand_v) > _FINE_ABOVE:
            from ..drive import build_drive

            fine_drive = build_drive(drive.design, tol=drive.tol / _FINE)
            ref = ImperfectScene.from_scene(Scene(fine_drive), imp)
            rot, shift = _poses_of(drive, imp, angles, cand_a, cand_k, cand_s, sections)
            # in batches: a candidate on the finer polygons holds ~18 kB while measured, and their number
            # grows with the sampling density (2900 at 0.05 deg on D1 [S4])
            cand_v = np.concatenate(
                [
                    clearance_at_poses(ref, rot[a : a + _FINE_BATCH], shift[a : a + _FINE_BATCH])["min"]
                    for a in range(0, len(rot), _FINE_BATCH)
                ]
            )
            n_fine = len(cand_v)
            o = np.argsort(cand_v, kind="stable")
            cand_v, cand_a, cand_k, cand_s = cand_v[o], cand_a[o], cand_k[o], cand_s[o]
            keep = cand_v <= cand_v[0] + 2.0 * ref.chord_gap
            cand_v, cand_a, cand_k, cand_s = cand_v[keep], cand_a[keep], cand_k[keep], cand_s[keep]
        exact_best = np.inf
        at = 0
        while at < len(cand_v):
            if cand_v[at] - ref.chord_gap >= exact_best:
                break
            # a refinement's cost is mostly per call: a few candidates go in one call, many in two
            # (the 16 lowest set the bar for the rest)
            first = len(cand_v) if len(cand_v) <= _ONE_CALL else 16
            live = np.nonzero(cand_v[at:] - ref.chord_gap < exact_best)[0] + at if at else np.arange(first)
            if live.size == 0:
                break
            rot, shift = _poses_of(drive, imp, angles, cand_a[live], cand_k[live], cand_s[live], sections)
            vals = refine_min(isc, rot, shift, clearance_at_poses(isc, rot, shift))["min"]
            n_refined += len(vals)
            j = int(np.argmin(vals))
            if vals[j] < exact_best:
                exact_best, where = float(vals[j]), int(live[j])
            at = int(live[-1]) + 1 if at == 0 else len(cand_v)
        best = exact_best
    if progress is not None:
        progress(900, 1000, "refine")
    ai, k, si = int(cand_a[where]), int(cand_k[where]), int(cand_s[where])
    z_w = sections[si]
    rot, shift = _poses_of(drive, imp, angles, np.array([ai]), np.array([k]), np.array([si]), sections)
    det = clearance_at_poses(isc, rot, shift, area=True)
    side = min(("lower", "upper", "third"), key=lambda s: det[s][0])
    j = int(det["lo"][0] if side == "lower" else det["up"][0] if side == "upper" else det["th"][0])
    area = det.get(f"{side}_area", np.zeros(1))[0] if side != "third" else 0.0
    phi_tooth = float((2 * pi * k / z_g + angles[ai] / scene.ratios["u_hg"] - angles[ai] + pi) % (2 * pi) - pi)
    phi_major = float((phi_tooth + pi / scene.n_w) % (2 * pi / scene.n_w) - pi / scene.n_w)
    worst = Finding(
        "min_clearance",
        float(best),
        "exact" if settings.refine else "polygon",
        tooth_angle=phi_major,
        section_z=z_w,
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
    # entry gap and pinch: every passage of a tooth through the entry in the swept angles, each with its
    # own crossing (wgcad.clearance.imperfect_entry), found from the perfect drive's (polygons suffice there:
    # they only say where to look)
    from .entry import entry_crossings, entry_pinch
    from .imperfect_entry import imperfect_entry

    if progress is not None:
        progress(920, 1000, "entry gap")
    gaps = list(zip(entry_crossings(scene, sections, exact=False), sections))
    crossed = any(np.isfinite(g[0]) for g, _ in gaps)
    p_pinch = entry_pinch(scene, [(g[1], z) for g, z in gaps if np.isfinite(g[0])], exact=False) if crossed else None
    # with the cam-borne offset alone (or no errors) every passage of a section is congruent (the mesh period
    # holds, docs/models.md 7): one passage per section stands for all
    span = np.array([angles[0], angles[0] + 2 * pi / scene.z_b]) if shortcuts(imp)["mesh_period"] else angles
    ent = imperfect_entry(drive, imp, isc, scene, gaps, p_pinch, span, sections, settings.refine) if crossed else {}
    # backlash of the imperfect drive at the first generator angle, middle section: the rigid turn of the
    # flexspline between contact either way, from the exact poses (wgcad.clearance.closing.closing_direct)
    z_mid = sections[len(sections) // 2]
    bl = _backlash(drive, imp, float(angles[0]), z_mid)
    if progress is not None:
        progress(1000, 1000, "done")
    sc = shortcuts(imp)
    bw = drive.design.drive.face_width
    ends = (not drive.coned) or (min(sections) <= 1e-9 and max(sections) >= bw - 1e-9)
    rs = {
        "engine": "2d",
        "angles": int(A),
        "angle_step_deg": round(float(np.rad2deg(np.median(np.diff(angles)))), 6) if A > 1 else None,
        "sections_z_mm": [None if z is None else round(z, 6) for z in sections],
        "sections_note": (
            "identical sections (no coning): one computed"
            if not drive.coned
            else "coned: every section computed" + ("" if ends else "; the face ends were NOT checked")
        ),
        "face_ends_checked": bool(ends),
        "mesh_period": False,
        "identical_waves": False,
        "mirror_symmetry": False,
        "culling": bool(settings.cull),
        "branch_and_bound": bool(settings.bound),
        "imperfections": True,
        "generator_turns": round(
            float((angles[-1] - angles[0]) / (2 * pi) + (np.median(np.diff(angles)) / (2 * pi) if A > 1 else 0.0)), 6
        ),
        "full_cycle_turns": int(full_cycle_turns(drive.design.drive.z_flex, drive.design.drive.z_rigid)),
        "shortcuts_that_hold": {
            k2: sc[k2] for k2 in ("mesh_period", "identical_waves", "mirror_symmetry", "one_generator_turn")
        },
        "shortcuts_note": (
            "imperfect parts: every (generator angle, tooth, section) sample posed with its errors, "
            f"in chunks of {B} generator angles; bounds only along a tooth's track ({sc['why']})"
        ),
        **accuracy_settings(drive, settings.refine),
        "working_flank": scene.working,
        "rigid_pitch_radius_mm": drive.rigid.r,
    }
    counts = {
        "samples": int(A * z_g * S),
        "unique_tooth_angles": int(A * z_g),
        "sections": S,
        "evaluated": int(n_ev),
        "culled": int(n_pruned),
        "perfect_evaluated": perfect.evaluated,
        "refined": int(n_refined),
        "fine_polygon": int(n_fine),
        "chunks": -(-A // B),
    }
    exact = "exact" if settings.refine else "polygon"
    rs["entry_side"] = "entry (+phi)" if scene.entry_sign > 0 else "entry (-phi)"
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
    findings = {
        "min_clearance": worst,
        "entry_gap": delta_f,
        "entry_crossing": gap_f,
        "entry_pinch": pinch_f,
        "backlash": Finding("backlash", float(bl), "brent", generator_angle=float(angles[0]), section_z=z_mid),
    }
    res = AuditResult(
        settings=rs,
        findings=findings,
        interference=best < -settings.interference_tol,
        interference_tol=settings.interference_tol,
        counts=counts,
        settings_angles=angles,
    )
    res.elapsed_s = time.perf_counter() - t0
    return res


def _entry_edge(drive, imp: Imperfections, isc: ImperfectScene, phi_h: float, k: int, z, exact: bool, rigid=None):
    """The edge (working / non-working) of the entry gap of tooth ``k`` at ``phi_h``, section ``z``, and where on
    the tooth it lies: the edge facing rigid tooth ``rigid`` or, without one, the edge with the smaller gap."""
    from .entry import EDGES, _edge_idx, edge_gaps

    rot, shift = flex_poses_batch(drive, imp, np.array([phi_h]), np.array([k]), [z])[0]
    shift = isc.relative(shift)
    idx = _edge_idx(isc, rot, shift)
    if rigid is None:
        e = int(np.argmin(edge_gaps(isc, rot, shift, exact=exact)[0]))
    else:
        e = 0 if int(idx[0][0]) == int(rigid) else 1
    return EDGES[e], _classify(isc, float(rot[0]), shift[0], int(idx[e][0]))


def _backlash(drive, imp: Imperfections, phi_h: float, z) -> float:
    """Dead travel (rad) of the imperfect drive at ``phi_h``: closing rotations either way; NaN if the teeth interfere."""
    from .closing import closing_direct

    if drive.design.drive.fixed != "rigid":
        return float("nan")
    up = closing_direct(drive, imp, phi_h, 1, sections=[z])
    dn = closing_direct(drive, imp, phi_h, -1, sections=[z])
    tot = up + dn
    if not np.isfinite(tot):
        return float("inf")
    return float(tot) if tot >= 0 and up >= 0 and dn >= 0 else float("nan")
