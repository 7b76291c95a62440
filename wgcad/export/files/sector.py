"""The files of a sectored rigid gear as a library call: heights and motion law (CSV, PNG), the sectored audit
PNG, the sectored rigid gear's DXF and STL and the summary JSON, written in one atomic batch. ``wgcad sector``
wraps it: flags, the bar, printing."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...atomic import atomic_batch
from ...plane import circle_polygon
from ...report.sector import heights_csv, loaded_csv, motion_csv, motion_phases_deg, summary_json
from ..formats.dxf import DxfLayer, write_dxf
from ..formats.json_text import json_text
from ..formats.stl import ring_solid, write_stl
from ..pictures import sector as sf

__all__ = ["write_sector_files"]


def write_sector_files(res: dict, source, out, *, stl: bool = True) -> tuple[dict, list]:
    """Write the files of :func:`wgcad.sector.run.run_sector`'s result ``res`` for the design file ``source``
    into the folder ``out``; return the summary document (the JSON written) and the paths written."""
    out, stem = Path(out), Path(source).stem
    lay, cf, reg, sim = res["layout"], res["boundary"], res["register"], res["simulated"]
    drive, law = res["drive"], res["motion"]
    summ = summary_json(res)
    bounds = np.rad2deg(lay.bounds)
    name = drive.design.drive.name
    png_h = sf.heights_png(
        f"{name}: tooth heights (docs/models.md 2.3), built: {res['mode']}",
        np.rad2deg(lay.centres),
        bounds,
        lay.kinds,
        res["full"],
        cf.heights,
        reg.heights,
        sim.heights,
        res["built"],
        tip_clearance_um=1e3 * res["tip_clearance"],
        sector=lay.sector,
    )
    phi_h = np.linspace(0.0, 2.0 * np.pi, 3601)
    png_m = sf.motion_png(
        f"{name}: motion law (rigid gear fixed), {summ['motion_law']['output_per_turn_deg']:.4f} deg per generator turn",
        np.rad2deg(phi_h),
        np.rad2deg(law(phi_h)),
        motion_phases_deg(law),
        list(bounds),
        lay.kinds,
    )
    curves = {
        "full height": 1e3 * res["audit_full"].per_tooth_min,
        f"built ({res['mode']})": 1e3 * res["audit_built"].per_tooth_min,
    }
    png_a = sf.audit_png(
        f"{name}: sectored audit over the cycle ({res['step_deg']:g} deg steps)",
        np.rad2deg(lay.centres),
        bounds,
        lay.kinds,
        curves,
        -1e3 * res["audit_built"].interference_tol,
        tip_curves={
            "full height": 1e3 * res["audit_full"].per_tooth_tip,
            f"built ({res['mode']})": 1e3 * res["audit_built"].per_tooth_tip,
        },
    )
    layers = [
        DxfLayer("RIGID_SECTORED", outlines=(res["outline"],), color=1),
        DxfLayer("RIGID_RIM", circles=((0.0, 0.0, drive.rigid_rim_radius),), color=1),
    ]
    mesh = None
    if stl:
        rim = circle_polygon(drive.rigid_rim_radius, drive.tol)
        mesh = ring_solid(rim, [res["outline"]], drive.design.drive.face_width)
    texts = {
        "heights.csv": heights_csv(res),
        "motion.csv": motion_csv(law),
        "sector.json": json_text(summ) + "\n",
    }
    pngs = {"heights.png": png_h, "motion.png": png_m, "sector_audit.png": png_a}
    suffixes = ["heights.csv", "heights.png", "motion.csv", "motion.png", "sector_audit.png"]
    cy = res.get("loaded")
    if cy is not None:
        low = np.asarray(cy.heights) < res["full"] - 1e-9
        texts["loaded.csv"] = loaded_csv(cy)
        pngs["loaded.png"] = sf.loaded_png(
            f"{name}: transitions under {cy.torque_nm:g} N m (elastic model at the motion law's knots)",
            np.rad2deg(cy.phi_h),
            np.rad2deg(cy.deviation) * 3600.0,
            cy.rigid_forces.max(axis=1),
            cy.rigid_forces[:, low].max(axis=1) if low.any() else np.zeros(len(cy.phi_h)),
            list(bounds),
            lay.kinds,
            dwells_deg=[(p["start_deg"], p["end_deg"]) for p in motion_phases_deg(law) if p["kind"] == "dwell"],
        )
        suffixes += ["loaded.csv", "loaded.png"]
    files = []
    with atomic_batch() as batch:
        for suffix in suffixes:
            path = out / f"{stem}_{suffix}"
            if suffix in texts:
                Path(batch.temp_path(path)).write_text(texts[suffix])
            else:
                Path(batch.temp_path(path)).write_bytes(pngs[suffix])
            files.append(path)
        path = out / f"{stem}_sector_rigid.dxf"
        write_dxf(batch.temp_path(path), layers)
        files.append(path)
        if mesh is not None:
            path = out / f"{stem}_sector_rigid.stl"
            write_stl(batch.temp_path(path), mesh)
            files.append(path)
        path = out / f"{stem}_sector.json"
        Path(batch.temp_path(path)).write_text(texts["sector.json"])
        files.append(path)
    return summ, files
