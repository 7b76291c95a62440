"""The title block of every part drawing: what the part is, from which design, units and scale, the material as the design states it (text only: nothing a CAM program would cut)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wgcad import __version__

from ..formats.dxf import DxfLayer

__all__ = ["TITLES", "drawing_extents", "title_layer"]

#: what each part of the set is, as a shop names it
TITLES = {
    "flexspline": "flexspline (cup), toothed rim in top view",
    "rigid": "rigid gear (circular spline) with its flange",
    "plug": "wave-generator plug (cam)",
    "generator": "external generator ring (its inner contour is the neutral line offset by the bearing)",
}


def drawing_extents(layers) -> tuple[float, float, float, float]:
    """``(x0, y0, x1, y1)`` of every outline, arc path vertex, circle and text anchor of the drawing, mm."""
    pts = []
    for lay in layers:
        pts += [np.asarray(o, float).reshape(-1, 2) for o in lay.outlines]
        pts += [np.asarray(p[0], float).reshape(-1, 2) for p in lay.paths]
        for cx, cy, r in lay.circles:
            pts.append(np.array([[cx - r, cy - r], [cx + r, cy + r]]))
        for x, y, h, text in lay.texts:
            pts.append(np.array([[x, y], [x + 0.6 * h * len(text), y + h]]))
    allp = np.concatenate(pts) if pts else np.zeros((1, 2))
    return float(allp[:, 0].min()), float(allp[:, 1].min()), float(allp[:, 0].max()), float(allp[:, 1].max())


def title_layer(part_name: str, design, source, layers, tol: float) -> DxfLayer:
    """The ``TITLE`` text layer, below the drawing's extents (left-aligned with them)."""
    x0, y0, x1, y1 = drawing_extents(layers)
    heights = [t[2] for lay in layers for t in lay.texts]
    h = 1.25 * max(heights) if heights else max(0.5, round(0.012 * max(x1 - x0, y1 - y0), 1))
    mat = design.material
    base = part_name.split("_")[0]
    if base != "flexspline":
        material = "material: not given by the design ([material] is the flexspline's)"
    elif mat.ultimate_strength_mpa is not None:
        material = f"material: as the design states: E = {mat.youngs_modulus_gpa:g} GPa, S_u = {mat.ultimate_strength_mpa:g} MPa"
        material += f", S_y = {mat.yield_strength_mpa:g} MPa" if mat.yield_strength_mpa is not None else ""
    else:
        material = f"material: not named by the design (its models take E = {mat.youngs_modulus_gpa:g} GPa)"
    lines = [
        f"TITLE: {design.drive.name} - {TITLES.get(base, part_name)}",
        f"design file: {Path(str(source)).name} | part: {part_name}",
        "units: mm | scale: 1:1 (drawn full size) | angles: degrees",
        material,
        f"outline: within {tol * 1e3:g} um of the exact curves; inspection figures in the data block",
        f"drawn by wgcad {__version__}",
    ]
    top = y0 - 3.0 * h
    texts = tuple((x0, top - 1.6 * h * k, h, line) for k, line in enumerate(lines))
    return DxfLayer("TITLE", texts=texts, color=7)
