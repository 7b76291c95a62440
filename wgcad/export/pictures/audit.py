"""The audit's pictures: what each one shows is computed here from the drive and the result, drawn by :mod:`wgcad.export.pictures.drive`."""

from __future__ import annotations

import numpy as np
import shapely

from ...clearance.engine import Scene, clearance_profile, clearance_vs_angle
from ...clearance.entry import entry_crossings
from ...clearance.imperfect import ImperfectScene, flex_poses_batch
from ...placement import tooth_pose, transform
from ...placement.imperfect import Imperfections
from ...report.audit import audit_json
from .drive import clearance_profile_png, clearance_vs_angle_png, tightest_spot_png
from .imperfect import entry_passages_png

__all__ = ["EXACT_BAND_MM", "audit_plot_data", "audit_pngs", "exact_near_minimum", "tightest_points"]


def audit_pngs(drive, result, data: dict | None = None):
    """The audit's pictures as ``(suffix, PNG bytes)``: the clearance profile of a passage, the clearance against
    generator angle (every passage's entry gap for an imperfect drive), the teeth around the tightest spot."""
    data = audit_plot_data(drive, result) if data is None else data
    yield "profile", clearance_profile_png(*data["profile"])
    kind, args = data["vs_angle"]
    if kind == "passages":
        yield "vs_angle", entry_passages_png(*args)
    else:
        yield "vs_angle", clearance_vs_angle_png(*args)
    yield "tightest", tightest_spot_png(*data["tightest"])


def audit_plot_data(drive, result) -> dict:
    """What the audit's pictures show, computed once for every renderer (PNG, the interactive page): ``profile``
    (data, title), ``vs_angle`` ("passages" or "curve", the arguments of its figure), ``tightest`` (teeth, labels,
    rigid teeth, overlaps, title), all in um and degrees."""
    scene = Scene(drive)
    imperfect = result.settings.imperfect is not None
    secs = [None] if not drive.coned else list(result.settings.sections)
    prof = exact_near_minimum(scene, clearance_profile(scene, secs))
    doc = audit_json(result)
    name = drive.design.drive.name
    perfect_note = " (perfect drive)" if imperfect else ""
    out = {
        "profile": (
            _profile_data(scene, secs, prof, result, doc, imperfect),
            f"{name}: clearance of a flexspline tooth along its passage (every tooth follows it){perfect_note}",
        )
    }
    out["vs_angle"] = _vs_angle(drive, result, scene, prof, secs, imperfect)
    out["tightest"] = _tightest(drive, scene, doc["worst"], imperfect)
    return out


#: how far above a flank's smallest figure the passage profile is refined on the exact curves, mm: every value the
#: figure against generator angle reads (the smallest over the teeth lies within a ripple of the minimum)
EXACT_BAND_MM = 0.05


def exact_near_minimum(scene, prof: dict, band: float = EXACT_BAND_MM) -> dict:
    """The passage profile (:func:`wgcad.clearance.engine.clearance_profile`, on the polygons) with every sample
    within ``band`` (mm) of its flank's smallest refined on the exact curves, so the pictures' minima are the
    audit's (the polygons read up to ``chord_tol`` off; the profile's far samples stay polygon figures)."""
    phi = np.asarray(prof["phi"], float)
    out = []
    for sec in prof["sections"]:
        rot, shift = scene.pose(phi, sec["z"])
        lo, up, _ = scene.neighbours(shift, rot)
        new = dict(sec)
        for key, idx in (
            ("working", up if scene.working == "upper" else lo),
            ("nonworking", lo if scene.working == "upper" else up),
        ):
            val = np.asarray(sec[key], float).copy()
            fin = np.isfinite(val)
            need = np.nonzero(fin & (val <= (val[fin].min() if fin.any() else 0.0) + band))[0]
            if need.size:
                val[need] = scene.exact_to(rot[need], shift[need], idx[need])[0]
            new[key] = val
        out.append(new)
    return {**prof, "sections": out}


def _profile_data(scene, secs, prof, result, doc, imperfect: bool) -> dict:
    """The passage profile's curves per section, the entry gap (the perfect drive's, and the imperfect parts' beside
    it) and the tightest spot."""
    w, e = doc["worst"], doc["entry"]
    ent = result.findings["entry_crossing"].details
    extra = {}
    if imperfect and "perfect_gaps" in ent:
        # the perfect drive's curve with its own entry crossing (on the exact curves) marked, and the imperfect
        # parts' entry gap beside it (every passage has its own picture)
        gaps = entry_crossings(scene, secs, exact=True)
        i = int(np.nanargmin([g for g, _ in gaps]))
        entry_deg, entry_um = float(np.rad2deg(gaps[i][1])), 1e3 * gaps[i][0]
        entry_label = "perfect drive's entry gap"
        if np.isfinite(result.entry_gap):
            extra = {
                "entry2_deg": e["tooth_angle_deg"],
                "entry2_um": 1e3 * result.entry_gap,
                "entry2_label": f"imperfect parts' entry gap Delta (tooth {e.get('pinch_tooth' if e.get('kind') == 'pinch' else 'tooth')}, the smallest of "
                f"{ent.get('passages', 0)} passages)",
            }
    else:
        entry_deg, entry_um, entry_label = e["tooth_angle_deg"], 1e3 * result.entry_gap, "entry gap Delta"
    return {
        "phi_deg": np.rad2deg(prof["phi"]),
        "sections": [
            {"z": s["z"], "working_um": 1e3 * s["working"], "nonworking_um": 1e3 * s["nonworking"]}
            for s in prof["sections"]
        ],
        "entry_deg": entry_deg,
        "entry_um": entry_um,
        "entry_label": entry_label,
        **extra,
        "worst_label": "imperfect parts' minimum" if imperfect else "minimum",
        "worst_deg": w["tooth_angle_deg"],
        "worst_um": w["clearance_um"],
        "tol_um": 1e3 * result.interference_tol,
    }


def _vs_angle(drive, result, scene, prof, secs, imperfect: bool) -> tuple:
    """The smallest clearance against the generator angle (three mesh periods), or, where the errors break the mesh
    period, the entry gap of every passage."""
    name = drive.design.drive.name
    ent = result.findings["entry_crossing"].details
    mesh = 360.0 / drive.design.drive.z_rigid
    if imperfect and "all_passages" in ent:
        # the errors break the mesh period: every passage of a tooth through the entry has its own gap
        a = ent["all_passages"]
        return (
            "passages",
            (
                np.rad2deg(a["phi_h"]),
                1e3 * a["gap"],
                a["section"],
                secs,
                [1e3 * g for g in ent["perfect_gaps"]],
                1e3 * result.interference_tol,
                f"{name}: entry gap of every passage of a tooth through the entry, imperfect parts "
                f"({round(result.settings.imperfect.generator_turns, 6) if imperfect else 1:g} generator turn(s); the audit's smallest is refined on the exact curves)",
            ),
        )
    perfect_note = " (perfect drive)" if imperfect else ""
    ang = np.deg2rad(np.linspace(0.0, 3 * mesh, 601))
    wv, nv = clearance_vs_angle(scene, prof, ang)
    return (
        "curve",
        (
            np.rad2deg(ang),
            1e3 * wv,
            1e3 * nv,
            1e3 * result.interference_tol,
            f"{name}: smallest clearance over all teeth; periodic with the mesh period {mesh:.4f} deg (3 shown){perfect_note}",
            None if imperfect else 1e3 * result.min_clearance,
        ),
    )


def _tightest(drive, scene, w: dict, imperfect: bool) -> tuple:
    """The teeth around the tightest spot, at the worst sample's generator angle and section, and their overlaps."""
    name = drive.design.drive.name
    phi_h = np.deg2rad(w["generator_angle_deg"])
    z = w["section_z_mm"]
    d = drive.design.drive
    k = (w["tooth"] + np.arange(-3, 4)) % d.z_flex
    mat = 2 * np.pi * k / d.z_flex + phi_h / scene.ratios["u_hg"]
    rot, shift = tooth_pose(scene.law(z), mat - phi_h, drive.r_m, frame_angle=phi_h)
    if imperfect:
        # the imperfect drive's own teeth, where the audit found its tightest spot
        imp = Imperfections.from_spec(drive.design.imperfections)
        scene = ImperfectScene.from_scene(scene, imp)
        rot, shift = flex_poses_batch(drive, imp, np.full(len(k), phi_h), k, [z])[0]
        shift = scene.relative(shift)  # drawn in the frame of the rigid gear's own centre
    teeth = transform(scene.flex_local, rot, shift)
    lo, up, _ = scene.neighbours(shift, rot)
    rig_idx = np.unique(np.concatenate([lo, up]))
    rig = scene.rigid_pts[rig_idx]
    overlaps = []
    for t in teeth[3:4]:  # the worst tooth
        a = shapely.Polygon(t)
        for j in rig_idx:
            inter = a.intersection(scene.rigid_geoms[j])
            for g in getattr(inter, "geoms", [inter]):
                if g.geom_type == "Polygon" and not g.is_empty:
                    overlaps.append(np.asarray(g.exterior.coords))
    labels = [f"{np.rad2deg(((p + np.pi) % (2 * np.pi)) - np.pi):.1f} deg" for p in (mat - phi_h)]
    sec = "" if z is None else f", section z = {z:g} mm"
    spot = tightest_points(scene, rot[3], shift[3], rig_idx)
    spot["label"] = f"tightest spot: {w['clearance_um']:.2f} um ({w['location']})"
    return (
        teeth,
        labels,
        rig,
        overlaps,
        f"{name}{' (imperfect parts)' if imperfect else ''}: tightest spot, tooth {w['tooth']} at generator angle {w['generator_angle_deg']:g} deg{sec}: "
        f"{w['clearance_um']:.2f} um ({w['location']})",
        spot,
    )


def tightest_points(scene, rot: float, shift: np.ndarray, rig_idx: np.ndarray) -> dict:
    """Where the worst tooth at pose ``(rot, shift)`` comes nearest a rigid tooth of ``rig_idx``, on the exact curves
    (the audit's figure, not the outlines'): ``um`` the signed clearance, ``flex`` and ``rigid`` the two ends of the
    gap (mm, the drawing's frame); where the teeth overlap, one point of the deepest penetration for both."""
    n = len(rig_idx)
    rots, shifts = np.full(n, float(rot)), np.tile(np.asarray(shift, float), (n, 1))
    val, side, pt = scene.exact_to(rots, shifts, rig_idx)
    j = int(np.nanargmin(val))
    rj = rig_idx[j : j + 1]
    if val[j] > 0.0:
        dist, solved, pa, pb = scene.apart_to(rots[:1], shifts[:1], rj)
        if solved[0]:
            # both ends in the rigid tooth's frame, drawn in the gear's
            ends = transform(np.stack([pa[0], pb[0]]), scene.rigid_rot[rj], scene.rigid_shift[rj])[0]
            return {"um": 1e3 * float(dist[0]), "flex": ends[0], "rigid": ends[1]}
    # side 0: a point of the flexspline tooth in the rigid tooth's frame; side 1: of the rigid tooth in the flexspline's
    if side[j] == 0:
        p = transform(pt[j][None], scene.rigid_rot[rj], scene.rigid_shift[rj])[0, 0]
    else:
        p = transform(pt[j][None], rots[:1], shifts[:1])[0, 0]
    return {"um": 1e3 * float(val[j]), "flex": p, "rigid": p}
