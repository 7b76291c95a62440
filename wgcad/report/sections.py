"""The audit section by section: how the mesh of a coned cup changes along the face (docs/models.md 13.4).

On a coned cup the deformation, and with it the depth of engagement and the
clearance, changes along the face width; a conjugate pair is conjugate at
one section only, and a face modification (``[flexspline]
face_modification``) is judged by how evenly it spreads both over the face.
This runs the clearance audit once per section (each its own exact audit
over the same generator angles) and puts the figures side by side.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..clearance.engine import audit
from ..roots import brentq

__all__ = ["section_rows", "section_lines", "balanced_taper"]


def engagement_depth(drive, z: float | None) -> float:
    """Depth of engagement on the major axis at section ``z``, mm: how far the flexspline's tip circle, carried out by
    the law's ``w(0)`` and the section's tooth offset, reaches past the rigid gear's tip circle (internal deformation;
    external: the other way)."""
    law = drive.law if z is None else drive.law_at(z)
    w = float(law.state(np.array([0.0])).w[0])
    reach = drive.flex.r_a + law.tooth_offset + w
    return drive.rigid.r_a - reach if drive.external else reach - drive.rigid.r_a


def section_rows(drive, settings, progress=None) -> list[dict]:
    """One row per section of ``settings.sections`` (mm/rad inside, units in the keys of the row's figures).

    Each row: ``section_z_mm``, ``tooth_offset_um`` (face modification), ``engagement_depth_um``, and the
    smallest clearance over the generator angles of ``settings`` in that section alone (``min_clearance_um``,
    with ``tooth_angle_deg``, ``location``, ``method``), from its own audit.
    """
    zs = [None] if not drive.coned else [float(z) for z in settings.sections]
    rows = []
    for i, z in enumerate(zs):
        res = audit(drive, replace(settings, sections=np.array([0.0 if z is None else z])))
        f = res.findings["min_clearance"]
        rows.append(
            {
                "section_z_mm": None if z is None else round(z, 6),
                "tooth_offset_um": round(1e3 * drive.tooth_offset(z), 4),
                "engagement_depth_um": round(1e3 * engagement_depth(drive, z), 4),
                "min_clearance_um": round(1e3 * f.value, 4),
                "tooth_angle_deg": None if f.tooth_angle is None else round(float(np.rad2deg(f.tooth_angle)), 4),
                "location": f.location,
                "method": f.method,
            }
        )
        if progress is not None:
            progress(i + 1, len(zs))
    return rows


def _end_minima(drive, settings, refine: bool) -> tuple[float, float]:
    """Smallest clearance (mm) at the open end and at the inner end of the face, each section audited alone."""
    bw = drive.design.drive.face_width
    out = []
    for z in (0.0, bw):
        res = audit(drive, replace(settings, sections=np.array([z]), refine=refine))
        out.append(float(res.min_clearance))
    return out[0], out[1]


def balanced_taper(drive, settings) -> dict | None:
    """The linear face taper (um/mm) that leaves the same smallest clearance at both ends of the face.

    Coning changes the tooth's whole motion along the face, not only its depth, so an offset along the tooth's
    centre line that keeps the depth of engagement (``face_modification = 'depth'``) leaves the clearance
    uneven: a conjugate pair then gapes or interferes at one end. The balanced taper trades a little depth
    for an even clearance: the root of ``c(open end) - c(inner end)`` in the taper, on the polygon audit
    (within two chord tolerances of the exact figures; Brent's method to 0.001 um/mm), both ends then
    audited on the exact curves. None when the drive is not a coned internal-deformation cup or no taper
    within four times the depth-keeping one balances the ends.
    """
    g = drive.design.generator
    if not drive.coned or drive.external:
        return None
    scale = 1e3 * drive.design.w0 / (g.cone_length - g.generator_z)  # the depth-keeping taper, um/mm

    def h(t: float) -> float:
        c0, c1 = _end_minima(drive.with_face_taper(t), settings, refine=False)
        return c0 - c1

    lo, hi = 0.0, scale
    h_lo, h_hi = h(lo), h(hi)
    for step in (2.0, 4.0):
        if h_lo * h_hi <= 0:
            break
        lo, hi = (-step * scale, lo) if abs(h_lo) < abs(h_hi) else (hi, step * scale)
        h_lo, h_hi = h(lo), h(hi)
    if h_lo * h_hi > 0:
        return None
    t = float(brentq(h, lo, hi, xtol=1e-3))
    c0, c1 = _end_minima(drive.with_face_taper(t), settings, refine=settings.refine)
    return {
        "face_taper_um_per_mm": round(t, 3),
        "depth_taper_um_per_mm": round(scale, 3),
        "min_clearance_um": {"open_end": round(1e3 * c0, 4), "inner_end": round(1e3 * c1, 4)},
        "method": "exact" if settings.refine else "polygon",
    }


def section_lines(rows: list[dict], balanced: dict | None = None) -> list[str]:
    """The rows as a printed table."""
    out = ["  by section:  z mm   tooth offset um   depth of engagement um   smallest clearance um (where)"]
    for r in rows:
        z = "-" if r["section_z_mm"] is None else f"{r['section_z_mm']:g}"
        where = "" if r["tooth_angle_deg"] is None else f" ({r['location']} at {r['tooth_angle_deg']:+.2f} deg)"
        out.append(
            f"  {z:>17}   {r['tooth_offset_um']:>+15.1f}   {r['engagement_depth_um']:>22.1f}   "
            f"{r['min_clearance_um']:>+10.3f}{where}"
        )
    if balanced is not None:
        c = balanced["min_clearance_um"]
        out.append(
            f"  an even clearance: face_modification = 'linear' with face_taper_um_per_mm = "
            f"{balanced['face_taper_um_per_mm']:g} leaves {c['open_end']:+.3f} um at the open end and "
            f"{c['inner_end']:+.3f} um at the inner end ({balanced['method']}; the depth-keeping taper is "
            f"{balanced['depth_taper_um_per_mm']:g} um/mm)"
        )
    return out
