"""The deformed assembly at one generator angle, for visual checks: rigid gear, flexspline in axial slices (coning included), plug, each a prism of its deformed outlines."""

from __future__ import annotations

import numpy as np

from wgcad.export.formats.arcs import path_area
from wgcad.placement.deformed import deformed_state, rim_samples, rotate
from wgcad.plane import signed_area

from .bodies import plug_arcs, plug_outline
from .part import Part
from .recipe import circle_loop, path_loop, polygon_loop, prism

__all__ = ["deformed_assembly", "N_SLICES_CONED"]

#: Axial slices of a coned flexspline's toothed rim: each slice is the
#: deformed section at its middle (coning changes W0 linearly along the
#: axis, docs/models.md 3.1); 6 slices make the taper visible.
N_SLICES_CONED = 6

PI = np.pi


def _area(p) -> float:
    return abs(signed_area(p))


def deformed_assembly(drive, sizes, generator_angle_deg: float, tol: float) -> Part:
    """The drive at generator angle ``generator_angle_deg`` (counter-clockwise from +x, relative to the fixed member).

    Returns
    -------
    Part
        Members ``rigid``, ``flexspline`` (its axial slices) and ``plug``; the part set writes their meshes (STL,
        3MF), :mod:`wgcad.cad` hands out their solids.
    """
    d = drive.design.drive
    bw = d.face_width
    phi_abs = float(np.deg2rad(generator_angle_deg))
    k = N_SLICES_CONED if drive.coned else 1
    edges = np.linspace(0.0, bw, k + 1)
    slices = []
    vol = 0.0
    for z0, z1 in zip(edges[:-1], edges[1:]):
        # each slice the deformed section at its middle (the centre law without coning)
        st = deformed_state(drive, phi_abs, tol, z=0.5 * (z0 + z1) if drive.coned else None)
        outer, hole = (st.rim, st.flex_outline) if drive.external else (st.flex_outline, st.rim)
        slices.append((outer, hole, z0, z1))
        vol += (_area(outer) - _area(hole)) * (z1 - z0)
    phi_h, frame = st.phi_h, st.frame
    n_rim = len(rim_samples(drive, tol))
    rigid_outline = st.rigid_outline
    R = drive.rigid_rim_radius
    # the rims are exact circles in the solid (their mesh the inscribed polygons, within the chord tolerance)
    if drive.external:
        vol += (_area(rigid_outline) - PI * R * R) * bw
    else:
        vol += (PI * R * R - _area(rigid_outline)) * bw
    po = plug_outline(drive, sizes, n_rim)
    plug = rotate(rotate(po["outline"], phi_h), frame)
    # the plug's tangent arcs (the part's own) turned as its points are
    arcs = plug_arcs(drive, po, tol).rotated(phi_h + frame)
    plug_area = abs(path_area(arcs))
    pz0, pz1 = po["z_mm"] - 0.5 * sizes.bearing_width, po["z_mm"] + 0.5 * sizes.bearing_width
    if drive.external:
        R_out = float(np.hypot(*po["outline"].T).max()) + max(2.0, sizes.bearing_thickness)
        vol += (PI * R_out * R_out - plug_area) * (pz1 - pz0)
    else:
        vol += plug_area * (pz1 - pz0)
    teeth, rim = polygon_loop(rigid_outline, "teeth"), circle_loop(R, tol, "rim")
    seat = path_loop(arcs, plug, "seat")
    if drive.external:
        bodies = {
            "rigid": (prism(teeth, [rim], 0.0, bw),),
            "plug": (prism(circle_loop(R_out, tol, "rim"), [seat], pz0, pz1),),
        }
    else:
        bodies = {"rigid": (prism(rim, [teeth], 0.0, bw),), "plug": (prism(seat, [], pz0, pz1),)}
    # the flexspline's rim is the deformed curve's polygon (that curve is its exact outline, not a circle)
    roles = ("rim", "teeth") if drive.external else ("teeth", "bore")
    bodies["flexspline"] = tuple(
        prism(polygon_loop(outer, roles[0]), [polygon_loop(hole, roles[1])], z0, z1) for outer, hole, z0, z1 in slices
    )
    bodies = {n: bodies[n] for n in ("rigid", "flexspline", "plug")}
    tag = f"{generator_angle_deg:+08.3f}".replace("+", "p").replace("-", "m").replace(".", "_")
    info = {"generator_angle_deg": generator_angle_deg, "slices": k}
    lo = -max(R, float(np.hypot(*rigid_outline.T).max()))
    return Part(f"assembly_phi{tag}", [], bodies, vol, ((lo, lo, min(0.0, pz0)), (-lo, -lo, max(bw, pz1))), info)
