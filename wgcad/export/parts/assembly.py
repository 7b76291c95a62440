"""The deformed assembly at one generator angle as meshes for visual checks: rigid gear, flexspline in axial slices (coning included), plug."""

from __future__ import annotations

import numpy as np

from wgcad.errors import GeometryError
from wgcad.plane import signed_area

from ..mesh import concatenate
from .part import Part
from .solids import circle_points, prism_m, to_mesh

__all__ = ["deformed_assembly", "N_SLICES_CONED"]

#: Axial slices of a coned flexspline's toothed rim: each slice is the
#: deformed section at its middle (coning changes W0 linearly along the
#: axis, docs/models.md 3.1); 6 slices make the taper visible.
N_SLICES_CONED = 6


def _area(p) -> float:
    return abs(signed_area(p))


def deformed_assembly(drive, sizes, generator_angle_deg: float, tol: float) -> Part:
    """Meshes of the drive at generator angle ``generator_angle_deg`` (counter-clockwise from +x, relative to the fixed member).

    Returns
    -------
    Part
        ``mesh()`` is all bodies in one mesh; ``info["meshes"]`` has one
        mesh per body (``rigid``, ``flexspline``, ``plug``) for 3MF; there is
        no STEP solid (``make_solid`` raises).
    """
    from wgcad.placement.deformed import deformed_state, rim_samples, rotate

    from .bodies import plug_outline

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
    rim_c = circle_points(R, tol)
    if drive.external:
        vol += (_area(rigid_outline) - _area(rim_c)) * bw
    else:
        vol += (_area(rim_c) - _area(rigid_outline)) * bw
    po = plug_outline(drive, sizes, n_rim)
    plug = rotate(rotate(po["outline"], phi_h), frame)
    pz0, pz1 = po["z_mm"] - 0.5 * sizes.bearing_width, po["z_mm"] + 0.5 * sizes.bearing_width
    if drive.external:
        R_out = float(np.hypot(*po["outline"].T).max()) + max(2.0, sizes.bearing_thickness)
        ring = circle_points(R_out, tol)
        vol += (_area(ring) - _area(plug)) * (pz1 - pz0)
    else:
        vol += _area(plug) * (pz1 - pz0)
    meshes = {}

    def mesh():
        if not meshes:
            if drive.external:
                meshes["rigid"] = to_mesh(prism_m(rigid_outline, [rim_c], 0.0, bw))
                meshes["plug"] = to_mesh(prism_m(ring, [plug], pz0, pz1))
            else:
                meshes["rigid"] = to_mesh(prism_m(rim_c, [rigid_outline], 0.0, bw))
                meshes["plug"] = to_mesh(prism_m(plug, [], pz0, pz1))
            flex = None
            for outer, hole, z0, z1 in slices:
                s = prism_m(outer, [hole], z0, z1)
                flex = s if flex is None else flex + s
            meshes["flexspline"] = to_mesh(flex)
        return concatenate([meshes[n] for n in ("rigid", "flexspline", "plug")])

    def solid():
        raise GeometryError("the deformed assembly is exported as a mesh only")

    tag = f"{generator_angle_deg:+08.3f}".replace("+", "p").replace("-", "m").replace(".", "_")
    info = {"generator_angle_deg": generator_angle_deg, "slices": k, "meshes": meshes, "build_meshes": mesh}
    lo = -max(R, float(np.hypot(*rigid_outline.T).max()))
    return Part(f"assembly_phi{tag}", [], solid, mesh, vol, ((lo, lo, min(0.0, pz0)), (-lo, -lo, max(bw, pz1))), info)
