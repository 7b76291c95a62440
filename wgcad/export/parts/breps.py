"""The part set's solids as B-rep text without a CAD kernel (:mod:`wgcad.export.brep`): toothed rings, the cup on its
ring, the flanged rigid gear, the plug and the generator ring.

Each recipe checks that its faces meet only where it joins them (the cup's shell clear of the tooth roots, bolt holes
inside their annulus and apart); where they would not, it returns ``None`` and the part is built by OpenCASCADE's
booleans as before (:mod:`wgcad.export.step`).
"""

from __future__ import annotations

import numpy as np

from wgcad.export.arcs import arc_points
from wgcad.export.brep import Brep, circle_loop, path_loop, polygon_loop, prism, spline_loop

__all__ = ["teeth_loop", "hole_loops", "circle_loop", "ring", "cup", "flanged", "plug", "generator_ring"]

#: how far apart faces the recipes join must stay (mm): far above the files' 1e-7 mm confusion distance
MARGIN = 1e-3


def teeth_loop(path=None, polygon=None, material_left: bool = True) -> tuple[list, np.ndarray]:
    """The loop of a toothed outline (an arc path, or a polygon) and its radii (of points along every arc)."""
    if path is not None:
        v, b = np.asarray(path.vertices, float), np.asarray(path.bulges, float)
        pts = arc_points(v, np.roll(v, -1, axis=0), b, 9).reshape(-1, 2)
        return path_loop(v, b, material_left), np.hypot(*pts.T)
    pts = np.asarray(polygon, dtype=float)
    return polygon_loop(pts, material_left), np.hypot(*pts.T)


def _holes_fit(holes, r_in: float, r_out: float) -> bool:
    """Bolt holes ``(cx, cy, d)`` strictly inside the annulus ``r_in < r < r_out`` and clear of each other."""
    if not holes:
        return True
    h = np.asarray(holes, dtype=float)
    rc, r = np.hypot(h[:, 0], h[:, 1]), 0.5 * h[:, 2]
    if np.any(rc - r <= r_in + MARGIN) or np.any(rc + r >= r_out - MARGIN):
        return False
    gap = np.hypot(*(h[:, None, :2] - h[None, :, :2]).transpose(2, 0, 1)) - (r[:, None] + r[None, :])
    np.fill_diagonal(gap, np.inf)
    return bool(np.all(gap > MARGIN))


def hole_loops(holes) -> list:
    return [circle_loop(x, y, 0.5 * d, material_left=False) for x, y, d in holes]


def ring(outer: list, holes: list, z0: float, z1: float) -> Brep:
    """A ring or plate: one outer loop, hole loops, straight through."""
    return prism(outer, holes, z0, z1)


def cup(
    teeth: list, teeth_r: np.ndarray, r_rim: float, ts: float, L: float, td: float, r_bore: float, holes, bw: float
):
    """The cup flexspline: the toothed ring (teeth outside, bore ``r_rim``, ``0 <= z <= bw``) with the cup on it (shell
    ``r_rim .. r_rim + ts`` up to ``z = L``, diaphragm ``L - td .. L`` with the hub bore ``r_bore`` and bolt holes).

    One bore face runs from the ring's open end to the diaphragm; the ring's top face is the annulus between the
    teeth and the shell. ``teeth`` is one loop, or the loops at ``z = 0`` and ``z = bw`` of a face-modified ring
    (``teeth_r`` then the radii of both). ``None`` where the shell would reach the tooth roots or a hole leaves the
    diaphragm.
    """
    r_shell = r_rim + ts
    if not (teeth_r.min() > r_shell + MARGIN and 0 < r_bore < r_rim - MARGIN and L - td > bw + MARGIN):
        return None
    if not _holes_fit(holes, r_bore, r_rim):
        return None
    b = Brep()
    # a pair of loops: the face-modified ring, ruled between its sections at z = 0 and z = bw
    w_teeth = b.ruled_wall(*teeth, 0.0, bw) if isinstance(teeth, tuple) else b.wall(teeth, 0.0, bw)
    w_bore = b.wall(circle_loop(0.0, 0.0, r_rim, material_left=False), 0.0, L - td)
    w_shell = b.wall(circle_loop(0.0, 0.0, r_shell), bw, L)
    w_hub = b.wall(circle_loop(0.0, 0.0, r_bore, material_left=False), L - td, L)
    w_holes = [b.wall(loop, L - td, L) for loop in hole_loops(holes)]
    b.cap(0.0, False, [(w_teeth, True), (w_bore, True)])
    b.cap(bw, True, [(w_teeth, True), (w_shell, False)])
    b.cap(L, True, [(w_shell, True), (w_hub, True), *((w, True) for w in w_holes)])
    b.cap(L - td, False, [(w_bore, False), (w_hub, True), *((w, True) for w in w_holes)])
    return b


def flanged(teeth: list, teeth_r: np.ndarray, R: float, Rf: float, holes, bw: float, tf: float):
    """The internal rigid gear: teeth inside a ring of radius ``R`` over ``0 <= z <= bw - tf``, and the flange of
    radius ``Rf`` with its bolt holes over ``bw - tf <= z <= bw``. ``None`` where a hole leaves the flange's
    overhang or a tooth reaches the ring."""
    if teeth_r.max() >= min(R, Rf) - MARGIN:
        return None
    if tf >= bw:
        return prism(circle_loop(0.0, 0.0, Rf), [teeth, *hole_loops(holes)], 0.0, bw)
    if not (Rf > R + MARGIN and _holes_fit(holes, R, Rf)):
        return None
    zs = bw - tf
    b = Brep()
    w_teeth = b.wall(teeth, 0.0, bw)
    w_ring = b.wall(circle_loop(0.0, 0.0, R), 0.0, zs)
    w_flange = b.wall(circle_loop(0.0, 0.0, Rf), zs, bw)
    w_holes = [b.wall(loop, zs, bw) for loop in hole_loops(holes)]
    b.cap(0.0, False, [(w_ring, True), (w_teeth, True)])
    b.cap(zs, False, [(w_flange, True), (w_ring, False), *((w, True) for w in w_holes)])
    b.cap(bw, True, [(w_flange, True), (w_teeth, True), *((w, True) for w in w_holes)])
    return b


def plug(outline, r_bore: float, z0: float, z1: float) -> Brep:
    """The wave-generator plug: the periodic cubic B-spline through its outline points (as OpenCASCADE interpolates
    them), a central bore."""
    return prism(spline_loop(outline), [circle_loop(0.0, 0.0, r_bore, material_left=False)], z0, z1)


def generator_ring(outline, R_out: float, z0: float, z1: float) -> Brep:
    """The external generator ring: a circle outside, the B-spline outline as its hole."""
    return prism(circle_loop(0.0, 0.0, R_out), [spline_loop(outline, material_left=False)], z0, z1)
