"""The kinematic error of a design as a library call: the no-load KE with its document and summary, the KE under
load, the installation-angle scans (docs/models.md 6.2, 6.3). ``wgcad ke`` wraps it: flags, files, printing."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..accuracy import ke as K
from ..accuracy.ke_load import install_lever, loaded_ke
from ..placement.imperfect import Imperfections, shortcuts
from ..units import ARCSEC_PER_RAD

__all__ = ["KERun", "no_load", "add_loaded", "add_install_scan"]

_AS = ARCSEC_PER_RAD


@dataclass(slots=True)
class KERun:
    """A KE run: the drive and its errors, the contact table, the no-load results, and the JSON document ``doc``
    that ``wgcad ke --json`` writes; ``loaded`` and ``scan`` once :func:`add_loaded` / :func:`add_install_scan` ran."""

    drive: object
    imp: object
    tab: object
    res: object
    intr: object
    orders: np.ndarray
    amp: np.ndarray
    expected: dict
    doc: dict
    loaded: list = field(default_factory=list)
    scan: tuple | None = None


def no_load(drive, imp, per_mesh: int, source: str, progress=None) -> tuple[KERun, list[str]]:
    """The no-load KE over one flexspline revolution, the perfect parts' KE beside it, the spectrum; with the
    summary lines. ``progress(fraction, stage)`` follows the contact table (70 % of D2's run) and the rest."""
    tick = progress or (lambda f, stage: None)
    tick(0.0, "contact table")
    tab = K.contact_table(drive, imp, per_mesh, progress=lambda f: tick(0.7 * f, "contact table"))
    tick(0.7, "kinematic error")
    res = K.kinematic_error(drive, imp, table=tab)
    tick(0.8, "perfect parts")
    perfect = Imperfections()
    tab0 = tab if imp.cam_cam == 0.0 else K.contact_table(drive, perfect, per_mesh)
    intr = K.kinematic_error(drive, perfect, table=tab0, samples=per_mesh * drive.design.drive.z_rigid)
    orders, amp = K.spectrum(res)
    tick(1.0, "done")
    d = drive.design.drive
    expected = K.expected_orders(d.z_flex, d.z_rigid)
    top = np.argsort(amp)[::-1][:8]
    out = {
        "design": source,
        "engagement": res.engagement,
        "ke_pp_arcsec": round(res.ke_pp * _AS, 4),
        "intrinsic_ke_pp_arcsec": round(intr.ke_pp * _AS, 4),
        # the rigid turn between the flanks at each angle, no load (docs/models.md 6.2 calls it the lost motion;
        # docs/glossary.md): not the audit's backlash, not the datasheet's lost motion at +-4 % of the rated torque
        "free_play_arcsec": {
            "min": round(float(res.lost_motion.min()) * _AS, 4),
            "max": round(float(res.lost_motion.max()) * _AS, 4),
        },
        "samples": int(len(res.ke)),
        "per_mesh_period": per_mesh,
        "chord_tol_um": round(drive.tol * 1e3, 6),
        "generator_turns": round(res.turns, 6),
        "shortcuts": shortcuts(imp),
        "expected_orders": expected,
        "spectrum_top": [
            {"order": round(float(orders[i]), 4), "amplitude_arcsec": round(float(amp[i]) * _AS, 4)} for i in top
        ],
    }
    lines = [
        f"{d.name}: no-load KE over one flexspline revolution ({res.turns:g} generator turns, {len(res.ke)} angles)",
        f"  engagement: {res.engagement}; free play between the flanks (no load, each angle) "
        f"{out['free_play_arcsec']['min']:.1f} .. {out['free_play_arcsec']['max']:.1f} arcsec",
        f"  largest KE (peak to peak): {out['ke_pp_arcsec']:.2f} arcsec; perfect parts: "
        f"{out['intrinsic_ke_pp_arcsec']:.3f} arcsec",
        "  strongest orders: "
        + ", ".join(f"{s['order']:g} ({s['amplitude_arcsec']:.2f}'')" for s in out["spectrum_top"][:4]),
        f"  contacts measured on outlines within {out['chord_tol_um']:g} um of the exact curves (--chord-tol-um; "
        "docs/models.md 6.2: how the KE moves with it)",
    ]
    out["deep_overlap_fraction"] = round(res.deep_overlap_fraction, 4)
    out["validity_notes"] = _validity(res)
    lines += [f"  {n}" for n in out["validity_notes"]]
    sc = out["shortcuts"]
    lines.append(
        f"  shortcuts that hold: mesh period {sc['mesh_period']}, identical waves {sc['identical_waves']}, "
        f"mirror {sc['mirror_symmetry']} ({sc['why']})"
    )
    return KERun(drive, imp, tab, res, intr, orders, amp, expected, out), lines


def _validity(res) -> list[str]:
    """Where the linear error model of the no-load KE does not hold (docs/models.md 6.2): the notes the text, the
    JSON (``validity_notes``) and the page all carry."""
    out = []
    if res.deep_overlap_fraction > 0:
        out.append(
            f"WARNING: at {100 * res.deep_overlap_fraction:.1f} % of the angles the first contact is a pair that overlaps "
            f"so deeply (turning back > {K.DEEP_OVERLAP * _AS:.0f} arcsec to separate) that the linear error model does not "
            "hold there: the KE can be off by hundreds of arcsec (docs/models.md 6.2); reduce the interference or use the elastic model"
        )
    if res.lost_motion.min() < 0:
        out.append(
            "note: the teeth interfere (negative free play): the rigid-body position splits the interference; "
            "errors must stay well below the overlap for the linear model (docs/models.md 6.2) - under load use the elastic model"
        )
    return out


def _zones(L) -> dict:
    """How the load splits between the engagement zones over a loaded KE run ([S4]'s explanation, docs/models.md 6.3)."""
    from ..accuracy.ke_load import SINGLE_ZONE_SHARE

    lesser = np.nanmin(L.zone_share, axis=1) if L.zone_share.size else np.zeros(0)
    sz = L.single_zone
    return {
        "single_zone_share_below": SINGLE_ZONE_SHARE,
        "single_zone_fraction": round(L.single_zone_fraction, 4),
        "lesser_share_min": round(float(lesser.min()), 4) if lesser.size else None,
        "lesser_share_max": round(float(lesser.max()), 4) if lesser.size else None,
        "ke_pp_single_zone_arcsec": round(L.ke_range(sz) * _AS, 4),
        "ke_pp_two_zone_arcsec": round(L.ke_range(~sz) * _AS, 4),
        "share_per_sample": [[round(float(x), 4) for x in row] for row in L.zone_share],
    }


def add_loaded(run: KERun, torques, samples=None, install: bool = False, bar=None) -> list[str]:
    """The KE under each torque (elastic model at whole mesh periods, docs/models.md 6.3) and, with ``install``, the
    installation-angle lever under it: added to ``run.doc["loaded"]`` and ``run.loaded``; the summary lines.
    ``bar``: an object with ``start(label)``, ``set(fraction, label)``, ``close()`` (a progress bar), or None."""
    from ..elastic import build_model

    drive, imp, res, tab = run.drive, run.imp, run.res, run.tab
    model = build_model(drive)  # a design without [bearing] data: a one-line DesignError naming it
    lines = []
    run.doc["loaded"] = []
    for T in torques:
        if bar is not None:
            bar.start(f"{T:g} N m")
        L = loaded_ke(
            drive,
            imp,
            T,
            samples=samples,
            model=model,
            progress=(lambda i, n, T=T: bar.set(i / n, f"{T:g} N m")) if bar is not None else None,
        )
        if bar is not None:
            bar.close()
        idx = L.periods * tab.N
        nl = res.ke[idx] - res.ke[idx[0]]
        nl_pp = float(nl.max() - nl.min())
        run.loaded.append(L)
        run.doc["loaded"].append(
            {
                "torque_nm": T,
                "ke_pp_arcsec": round(L.ke_pp * _AS, 4),
                "samples": int(len(L.ke)),
                "no_load_ke_pp_at_samples_arcsec": round(nl_pp * _AS, 4),
                "mean_wind_up_arcsec": round(L.wind_up * _AS, 3),
                "teeth_in_contact": [int(L.teeth_in_contact.min()), int(L.teeth_in_contact.max())],
                "zones": _zones(L),
                "seconds": round(L.seconds, 3),
            }
        )
        z = run.doc["loaded"][-1]["zones"]
        lines.append(
            f"  under {T:g} N m (elastic model at {len(L.ke)} whole mesh periods over the revolution): largest KE "
            f"{L.ke_pp * _AS:.2f} arcsec against {nl_pp * _AS:.2f} at no load at the same angles; wind-up {L.wind_up * _AS:.1f} arcsec, "
            f"{L.teeth_in_contact.min()}-{L.teeth_in_contact.max()} tooth contacts"
        )
        lines.append(
            f"    zones: single-zone (the lesser zone under {100 * z['single_zone_share_below']:g} % of the torque) at "
            f"{100 * z['single_zone_fraction']:.1f} % of the samples; lesser zone's share {100 * z['lesser_share_min']:.1f}"
            f"-{100 * z['lesser_share_max']:.1f} %; KE within the single-zone samples {z['ke_pp_single_zone_arcsec']:.2f}'', "
            f"within the two-zone ones {z['ke_pp_two_zone_arcsec']:.2f}''"
        )
        if install:
            if bar is not None:
                bar.start(f"installation angle, {T:g} N m")
            lev = install_lever(
                drive,
                imp,
                T,
                model=model,
                samples=samples,
                design=L,
                progress=(lambda i, n, T=T: bar.set(i / n, f"installation angle, {T:g} N m"))
                if bar is not None
                else None,
            )
            if bar is not None:
                bar.close()
            run.doc["loaded"][-1]["install_angle"] = {
                "best_rigid_angle_deg": round(math.degrees(lev.best_angle), 3),
                "best_ke_pp_arcsec": round(lev.best.ke_pp * _AS, 4),
                "design_angle_deg": round(math.degrees(imp.rigid_install), 3),
                "design_ke_pp_arcsec": round(lev.design.ke_pp * _AS, 4),
                "lever": round(lev.lever, 4),
                "angles_deg": [round(float(a), 3) for a in np.degrees(lev.grid)],
                "rigid_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in lev.grid_pp],
                "scan_samples": lev.scan_samples,
                "seconds": round(lev.seconds, 3),
            }
            lines.append(
                f"    rigid gear installation angle under {T:g} N m: best {math.degrees(lev.best_angle):.1f} deg, largest KE "
                f"{lev.best.ke_pp * _AS:.2f} arcsec against {lev.design.ke_pp * _AS:.2f} at the design's "
                f"{math.degrees(imp.rigid_install):g} deg ({f'{lev.lever:.2f} times lower' if lev.lever > 1 else 'no angle does better'}; "
                f"scan of {len(lev.grid)} angles with "
                f"{lev.scan_samples} states each: {lev.grid_pp.min() * _AS:.1f} .. {lev.grid_pp.max() * _AS:.1f} arcsec)"
            )
    lines.append(
        "  under load NOT CHECKED: the KE within a mesh period (the elastic model has states at whole mesh periods only)"
    )
    return lines


def add_install_scan(run: KERun) -> list[str]:
    """The no-load installation-angle scans of the rigid gear (optimised) and the flexspline, into ``run.doc`` and
    ``run.scan``; the summary line."""
    best, best_pp, grid, pp = K.optimize_install_angle(run.tab, run.imp, "rigid")
    fpp = K.install_angle_scan(run.tab, run.imp, grid, "flex")
    run.scan = (np.degrees(grid), pp, math.degrees(best), best_pp, fpp)
    run.doc["install_angle"] = {
        "best_rigid_angle_deg": round(math.degrees(best), 3),
        "best_ke_pp_arcsec": round(best_pp * _AS, 4),
        "angles_deg": [round(float(a), 3) for a in np.degrees(grid)],
        "rigid_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in pp],
        "flex_ke_pp_arcsec": [round(float(v) * _AS, 4) for v in fpp],
    }
    return [
        f"  rigid gear installation angle: best {math.degrees(best):.2f} deg, largest KE {best_pp * _AS:.2f} arcsec "
        f"(range over angles {pp.min() * _AS:.2f} .. {pp.max() * _AS:.2f}); flexspline position: "
        f"{fpp.min() * _AS:.2f} .. {fpp.max() * _AS:.2f}"
    ]
