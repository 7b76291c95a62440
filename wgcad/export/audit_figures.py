"""The audit's pictures: what each one shows is computed here from the drive and the result, drawn by :mod:`wgcad.export.figures`."""

from __future__ import annotations

__all__ = ["audit_plot_data", "audit_pngs"]


def audit_pngs(drive, result, data: dict | None = None):
    """The audit's pictures as ``(suffix, PNG bytes)``: the clearance profile of a passage, the clearance against
    generator angle (every passage's entry gap for an imperfect drive), the teeth around the tightest spot."""
    from .figures import clearance_profile_png, clearance_vs_angle_png, tightest_spot_png

    data = audit_plot_data(drive, result) if data is None else data
    yield "profile", clearance_profile_png(*data["profile"])
    kind, args = data["vs_angle"]
    if kind == "passages":
        from .imperfect_figures import entry_passages_png

        yield "vs_angle", entry_passages_png(*args)
    else:
        yield "vs_angle", clearance_vs_angle_png(*args)
    yield "tightest", tightest_spot_png(*data["tightest"])


def audit_plot_data(drive, result) -> dict:
    """What the audit's pictures show, computed once for every renderer (PNG, the interactive page): ``profile``
    (data, title), ``vs_angle`` ("passages" or "curve", the arguments of its figure), ``tightest`` (teeth, labels,
    rigid teeth, overlaps, title), all in um and degrees."""
    from ..clearance.engine import Scene, clearance_profile
    from ..report.audit import audit_json

    scene = Scene(drive)
    imperfect = result.settings.imperfect is not None
    secs = [None] if not drive.coned else list(result.settings.sections)
    prof = clearance_profile(scene, secs)
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


def _profile_data(scene, secs, prof, result, doc, imperfect: bool) -> dict:
    """The passage profile's curves per section, the entry gap (the perfect drive's, and the imperfect parts' beside
    it) and the tightest spot."""
    import numpy as np

    w, e = doc["worst"], doc["entry"]
    ent = result.findings["entry_crossing"].details
    extra = {}
    if imperfect and "perfect_gaps" in ent:
        # the perfect drive's curve with its own entry crossing (on the exact curves) marked, and the imperfect
        # parts' entry gap beside it (every passage has its own picture)
        from ..clearance.entry import entry_crossings

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
    import numpy as np

    from ..clearance.engine import clearance_vs_angle

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
        ),
    )


def _tightest(drive, scene, w: dict, imperfect: bool) -> tuple:
    """The teeth around the tightest spot, at the worst sample's generator angle and section, and their overlaps."""
    import numpy as np
    import shapely

    from ..placement import tooth_pose, transform

    name = drive.design.drive.name
    phi_h = np.deg2rad(w["generator_angle_deg"])
    z = w["section_z_mm"]
    d = drive.design.drive
    k = (w["tooth"] + np.arange(-3, 4)) % d.z_flex
    mat = 2 * np.pi * k / d.z_flex + phi_h / scene.ratios["u_hg"]
    rot, shift = tooth_pose(scene.law(z), mat - phi_h, drive.r_m, frame_angle=phi_h)
    if imperfect:
        # the imperfect drive's own teeth, where the audit found its tightest spot
        from ..clearance.imperfect import ImperfectScene, flex_poses_batch
        from ..placement.imperfect import Imperfections

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
    return (
        teeth,
        labels,
        rig,
        overlaps,
        f"{name}{' (imperfect parts)' if imperfect else ''}: tightest spot, tooth {w['tooth']} at generator angle {w['generator_angle_deg']:g} deg{sec}: "
        f"{w['clearance_um']:.2f} um ({w['location']})",
    )
