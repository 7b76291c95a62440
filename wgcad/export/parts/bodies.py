"""The three bodies of a drive: cup flexspline (or toothed ring), wave-generator plug (or generator ring), rigid gear with flange and bolt holes."""

from __future__ import annotations

import math

import numpy as np
import shapely

from wgcad.errors import DesignError
from wgcad.export.formats.arcs import fit_closed_curve, fit_gear, path_area
from wgcad.export.formats.dxf import DxfLayer
from wgcad.export.formats.gear_data import data_lines, gear_data
from wgcad.placement import deformed_curve
from wgcad.plane import signed_area
from wgcad.profiles.band import gear_band_outline

from .part import Part
from .recipe import Body, Cap, Wall, circle_loop, path_loop, polygon_loop, prism
from .solids import bolt_circle

__all__ = ["flexspline", "plug", "rigid", "plug_outline", "plug_arcs", "data_layer"]

PI = math.pi


def data_layer(
    name: str, gear, tol: float, x: float, y: float, height: float, sectored: dict | None = None, face=None
) -> tuple:
    """The GEAR_DATA text layer (one TEXT per line, top line at ``y``) and the data dict (with ``sectored``: the
    sectors and every tooth's height, which the lines summarise per sector; with ``face``, a drive whose flexspline
    is modified along the face: how its teeth move from the reference section the figures hold at)."""
    data = gear_data(gear, tol)
    lines = data_lines(name, data)
    if face is not None:
        data["face_modification"] = face_modification(face)
        lines[3:3] = face_lines(face)
    if sectored is not None:
        lay, built, full = sectored["layout"], np.asarray(sectored["built"], float), float(sectored["full"])
        kind_of = [str(lay.kinds[int(s)]) for s in lay.sector]  # each tooth's sector kind
        data["sectors"] = {
            "teeth": int(lay.n_teeth),
            "heights_mode": sectored["mode"],
            "full_height_mm": full,
            "tooth_heights_mm": [round(float(h), 6) for h in built],
            "tooth_sector_kinds": kind_of,
            "layout": _sector_table(lay),
        }
        # the plain gear's tooth count and its span or pin dimension are not this gear's: its teeth have other
        # heights and pitches by sector (a pin dimension over lowered teeth checks nothing)
        skip = ("teeth z =", "span ", "  k:", "dimension ", "  pin:", "span / pins")
        lines = [line for line in lines if not line.startswith(skip)]
        data["span"] = data["pins"] = None
        lines.insert(-1, "span / pins: not given for a sectored gear (tooth heights differ by sector)")
        lines.insert(1, f"base gear: z = {gear.spec.z} ({data['form']}), module and flanks as below")
        lines.insert(2, f"SECTORED: {lay.n_teeth} teeth in sectors ({sectored['mode']} heights; full {full:.4f} mm)")
        lowered = np.nonzero(built < full - 1e-6)[0]
        lines.insert(3, f"lowered teeth: {len(lowered)} of {lay.n_teeth} (every height in the part set's JSON)")
        # the base gear's tip circle is the full teeth's only: a lowered tooth's tip stands at the root less its height
        k = next(i for i, line in enumerate(lines) if line.startswith("tip diameter ="))
        lines[k] = lines[k].replace("tip diameter =", "tip diameter (full teeth) =")
        if lowered.size:
            d = 2.0 * (gear.r_f - built[lowered])
            lines.insert(k + 1, f"tip diameters, lowered teeth = {d.min():.4f} .. {d.max():.4f} mm")
        for kind in dict.fromkeys(kind_of):
            sel = np.array([k == kind for k in kind_of])
            rows = [r for r in data["sectors"]["layout"] if r["kind"] == kind]
            counts = sorted({r["teeth"] for r in rows})
            pitch = sorted({r["pitch_deg"] for r in rows})
            lines.insert(
                4,
                f"  {kind}: {len(rows)} x {'/'.join(map(str, counts))} teeth at "
                f"{'/'.join(f'{q:.4f}' for q in pitch)} deg pitch, heights {built[sel].min():.4f} .. "
                f"{built[sel].max():.4f} mm",
            )
    texts = tuple((x, y - 1.6 * height * k, height, line) for k, line in enumerate(lines))
    return DxfLayer("GEAR_DATA", texts=texts, color=7), data, lines


def _sector_table(lay) -> list:
    """Each sector of the layout as the drawing states it: kind, teeth, angular pitch (the sectors' pitches differ,
    so the base gear's tooth count says nothing of them) and where it starts, degrees counter-clockwise."""
    rows = []
    for s, kind in enumerate(lay.kinds):
        sel = lay.sector == s
        rows.append(
            {
                "kind": str(kind),
                "teeth": int(sel.sum()),
                "pitch_deg": round(float(np.rad2deg(lay.pitch[sel][0])), 6),
                "start_deg": round(float(np.rad2deg(lay.bounds[s])), 6),
            }
        )
    return rows


def _band(gear):
    """The toothed outline as polyline: a symmetric band around the exact curves (docs/models.md, appendix A)."""
    return gear_band_outline(gear)


def _teeth_layer(name, gear, path, style, color, band=None):
    if style == "arcs":
        return DxfLayer(name, paths=(path,), color=color)
    return DxfLayer(name, outlines=(_band(gear) if band is None else band,), color=color)


def _pappus(rz) -> float:
    """Volume of the solid of revolution of a closed (r, z) polygon about z: 2 pi * integral of r dA (Green)."""
    r, z = np.asarray(rz, dtype=float).T
    r2, z2 = np.roll(r, -1), np.roll(z, -1)
    # integral of r dr dz over the polygon = -(1/2) closed integral of r^2 dz ... use exact per-edge form
    val = np.sum((z2 - z) * (r * r + r * r2 + r2 * r2)) / 6.0
    return 2.0 * PI * abs(float(val))


def flexspline(drive, sizes, style: str, tol: float) -> Part:
    """The cup flexspline (internal deformation) or the internally toothed flexible ring (external)."""
    g = drive.flex
    d = drive.design
    bw = d.drive.face_width
    path = fit_gear(g, tol)
    band = _band(g)
    area = abs(path_area(path))
    r_rim = drive.flex_rim_radius
    tip_r = float(np.hypot(*g.outline.T).max())
    text_h = max(0.5, round(0.02 * 2 * tip_r, 1))
    face = drive if drive.face_taper else None
    gl, data, lines = data_layer("flexspline", g, tol, 1.15 * tip_r, tip_r, text_h, face=face)
    layers = [_teeth_layer("FLEXSPLINE", g, path, style, 5, band)]
    info = {"gear_data": data}
    if drive.external:
        R = r_rim
        layers.append(DxfLayer("FLEXSPLINE_OUTER", circles=((0.0, 0.0, R),), color=5))
        layers.append(gl)
        vol = (PI * R * R - area) * bw
        body = prism(circle_loop(R, tol, "rim"), [path_loop(path, band, "teeth")], 0.0, bw)
        info["kind"] = "toothed flexible ring (external deformation: no cup)"
        return Part("flexspline", layers, {"flexspline": (body,)}, vol, ((-R, -R, 0.0), (R, R, bw)), info)
    L, ts, td = sizes.cup_length, sizes.shell_thickness, sizes.diaphragm_thickness
    r_bore = 0.5 * sizes.hub_bore_diameter
    holes = bolt_circle(sizes.cup_bolt_circle_diameter, sizes.cup_bolt_count, sizes.cup_bolt_hole_diameter)
    rz = np.array([[r_rim, bw], [r_rim + ts, bw], [r_rim + ts, L], [r_bore, L], [r_bore, L - td], [r_rim, L - td]])
    shell = _pappus(rz) - len(holes) * PI * (0.5 * sizes.cup_bolt_hole_diameter) ** 2 * td
    layers += [
        DxfLayer("FLEXSPLINE_BORE", circles=((0.0, 0.0, r_rim),), color=5),
        DxfLayer("CUP_SHELL", circles=((0.0, 0.0, r_rim + ts),), color=8),
        DxfLayer("HUB_BORE", circles=((0.0, 0.0, r_bore),), color=3),
        DxfLayer("CUP_BOLT_HOLES", circles=tuple((x, y, 0.5 * h) for x, y, h in holes), color=3),
        gl,
    ]
    if drive.face_taper:
        return _modified_cup(drive, sizes, tol, (layers, info), holes, shell)
    vol = (area - PI * r_rim**2) * bw + shell
    body = _cup(drive, sizes, tol, Wall(path_loop(path, band, "teeth"), 0.0, bw, True), holes)
    info.update(_cup_info(sizes, r_bore))
    return Part("flexspline", layers, {"flexspline": (body,)}, vol, ((-tip_r, -tip_r, 0.0), (tip_r, tip_r, L)), info)


#: how far apart the faces of a part must stay where its recipe joins them (mm), far above the kernel's 1e-7 mm
MARGIN = 1e-3


def _cup(drive, sizes, tol: float, teeth: Wall, holes) -> Body:
    """The cup flexspline's body: the toothed ring (``teeth``, bore ``r_rim``, ``0 <= z <= bw``) with the cup on it
    (shell ``r_rim .. r_rim + ts`` up to ``z = L``, diaphragm ``L - td .. L`` with the hub bore and bolt holes).

    One bore face runs from the ring's open end to the diaphragm; the ring's top face is the annulus between the
    teeth and the shell.
    """
    bw = drive.design.drive.face_width
    r_rim, L = drive.flex_rim_radius, sizes.cup_length
    ts, td, r_bore = sizes.shell_thickness, sizes.diaphragm_thickness, 0.5 * sizes.hub_bore_diameter
    roots = min(float(np.hypot(*w.polygon.T).min()) for w in (teeth.loop, teeth.top or teeth.loop))
    if not roots > r_rim + ts + MARGIN:
        raise DesignError("parts.shell_thickness", f"{ts:g} mm reaches the tooth roots (radius {roots:.4f} mm)")
    _holes_fit(holes, r_bore, r_rim, "parts.cup_bolt_circle_diameter")
    walls = (
        teeth,
        Wall(circle_loop(r_rim, tol, "bore"), 0.0, L - td, False),
        Wall(circle_loop(r_rim + ts, tol, "shell"), bw, L, True),
        Wall(circle_loop(r_bore, tol, "hub_bore"), L - td, L, False),
        *(Wall(circle_loop(0.5 * d, tol, "bolt_holes", x, y), L - td, L, False) for x, y, d in holes),
    )
    bolts = tuple((i, False) for i in range(4, len(walls)))
    return Body(
        walls,
        (
            Cap(0.0, False, ((0, True), (1, False)), "end"),
            Cap(bw, True, ((0, True), (2, False)), "rim_end"),
            Cap(L, True, ((2, True), (3, False), *bolts), "diaphragm"),
            Cap(L - td, False, ((1, True), (3, False), *bolts), "diaphragm_inside"),
        ),
    )


def _holes_fit(holes, r_in: float, r_out: float, field: str) -> None:
    """Bolt holes ``(cx, cy, d)`` strictly inside the annulus ``r_in < r < r_out`` and clear of each other, or a
    :class:`DesignError` on ``field`` (the sizes' own rules keep them so: this guards the faces the recipe joins)."""
    if not holes:
        return
    h = np.asarray(holes, dtype=float)
    rc, r = np.hypot(h[:, 0], h[:, 1]), 0.5 * h[:, 2]
    gap = np.hypot(*(h[:, None, :2] - h[None, :, :2]).transpose(2, 0, 1)) - (r[:, None] + r[None, :])
    np.fill_diagonal(gap, np.inf)
    if np.any(rc - r <= r_in + MARGIN) or np.any(rc + r >= r_out - MARGIN) or not np.all(gap > MARGIN):
        raise DesignError(field, f"the bolt holes leave the annulus {2 * r_in:.4f} .. {2 * r_out:.4f} mm or touch")


def face_modification(drive) -> dict:
    """How a face-modified flexspline's teeth move along the face (docs/models.md 13.4), units in the keys."""
    bw = drive.design.drive.face_width
    return {
        "kind": drive.design.flexspline.face_modification,
        "reference_z_mm": drive.face_reference_z,
        "taper_um_per_mm": round(1e3 * drive.face_taper, 4),
        "tooth_offset_um": {f"z_{z:g}_mm": round(1e3 * drive.tooth_offset(z), 3) for z in (0.0, bw)},
    }


def face_lines(drive) -> list[str]:
    """The data block's lines of a face-modified flexspline."""
    bw = drive.design.drive.face_width
    o0, o1 = (1e3 * drive.tooth_offset(z) for z in (0.0, bw))
    return [
        f"FACE-MODIFIED teeth: moved out along their centre lines by {1e3 * drive.face_taper:.4f} um per mm of z,",
        f"  {o0:+.1f} um at z = 0 (open end), {o1:+.1f} um at z = {bw:g} mm; the figures below hold at",
        f"  z = {drive.face_reference_z:g} mm (offset 0); tip and root diameters move with the offset",
    ]


def _cup_info(sizes, r_bore: float) -> dict:
    return {
        "kind": "cup flexspline",
        "cup_length_mm": sizes.cup_length,
        "shell_thickness_mm": sizes.shell_thickness,
        "diaphragm_thickness_mm": sizes.diaphragm_thickness,
        "hub_bore_diameter_mm": 2 * r_bore,
        "bolt_circle_diameter_mm": sizes.cup_bolt_circle_diameter,
        "bolt_count": sizes.cup_bolt_count,
        "bolt_hole_diameter_mm": sizes.cup_bolt_hole_diameter,
    }


def _modified_cup(drive, sizes, tol: float, drawn: tuple, holes, shell: float) -> Part:
    """The cup flexspline whose teeth are offset along the face (docs/models.md 13.4): the toothed ring lofted.

    The offset is linear in z and moves each tooth rigidly, so every point of the outline moves on a straight
    line: the ruled loft between the outlines at both ends of the face is the exact ring (STEP: ruled faces
    between corresponding arcs; mesh: the band outlines joined vertex to vertex). The drawing shows the
    reference section, where the offset is zero, and says how the teeth move from it.
    """
    g = drive.flex
    bw = drive.design.drive.face_width
    layers, info = drawn
    r_rim, L = drive.flex_rim_radius, sizes.cup_length
    ends = (0.0, bw)
    offs = [drive.tooth_offset(z) for z in ends]
    # the section's area is quadratic in the offset, the offset linear in z: Simpson's rule is exact
    areas = [abs(path_area(fit_gear(g, tol, drive.tooth_offset(z)))) for z in (0.0, 0.5 * bw, bw)]
    vol = bw * (areas[0] + 4 * areas[1] + areas[2]) / 6.0 - PI * r_rim**2 * bw + shell
    # the sections at both ends: the same arcs and band vertices moved, so they correspond one to one
    l0, l1 = (path_loop(fit_gear(g, tol, o), gear_band_outline(g, offset=o), "teeth") for o in offs)
    body = _cup(drive, sizes, tol, Wall(l0, 0.0, bw, True, top=l1), holes)
    info.update(_cup_info(sizes, 0.5 * sizes.hub_bore_diameter))
    info["face_modification"] = face_modification(drive)
    tip_r = float(np.hypot(*g.outline.T).max()) + max(0.0, *offs)
    return Part("flexspline", layers, {"flexspline": (body,)}, vol, ((-tip_r, -tip_r, 0.0), (tip_r, tip_r, L)), info)


def plug_outline(drive, sizes, n: int | None = None) -> dict:
    """Outline of the wave-generator plug (internal deformation) or the generator ring's bore (external).

    The flexible bearing's races bend with the flexspline and keep their
    radial section ``t_b``: the plug surface is the flexspline's deformed
    inner surface offset inward by ``t_b`` along its normal, i.e. the
    neutral line offset by ``-(h1/2 + t_b)`` (external deformation: outward
    by ``h1/2 + t_b``), docs/models.md 3. The law is the one at the
    generator's centre section (coned drives: ``drive.law_at(generator_z)``).

    Returns
    -------
    dict
        ``outline (n, 2)``, ``neutral (n, 2)``, ``offset_mm`` (signed, from
        the neutral line), ``z_mm`` (generator section), ``phi (n,)``.
    """
    d = drive.design
    bw = d.drive.face_width
    z_g = d.generator.generator_z if d.generator.generator_z is not None else 0.5 * bw
    law = drive.law_at(z_g) if drive.coned else drive.law
    half = drive.flex_rim_radius - drive.r_m  # -h1/2 (internal), +h1/2 (external)
    off = half + (1.0 if drive.external else -1.0) * sizes.bearing_thickness
    if n is None:
        # a circle of the neutral radius's count, then as many more as the chords' measured sagitta asks: an
        # outline outside the neutral line (an external drive's ring bore) has longer chords over the same angle
        # (D3's sagged 1.15 um at the circle's count against the 1 um tolerance)
        n = max(720, int(np.ceil(2 * np.pi / np.sqrt(8 * drive.tol / drive.r_m))))
        for _ in range(5):
            sag = _chord_sagitta(law, drive.r_m, off, n)
            if sag <= drive.tol:
                break
            n = int(np.ceil(n * np.sqrt(sag / (0.95 * drive.tol))))
    ph = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    neutral = deformed_curve(law, drive.r_m, 0.0, ph)
    outline = deformed_curve(law, drive.r_m, off, ph)
    return {"outline": outline, "neutral": neutral, "offset_mm": off, "z_mm": z_g, "phi": ph}


def _chord_sagitta(law, r_m: float, off: float, n: int) -> float:
    """Largest distance of the offset curve from its ``n`` equal-angle chords, at the chords' middle angles, mm."""
    ph = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    a = deformed_curve(law, r_m, off, ph)
    ab = np.roll(a, -1, axis=0) - a
    m = deformed_curve(law, r_m, off, ph + np.pi / n) - a
    return float(np.max(np.abs(ab[:, 0] * m[:, 1] - ab[:, 1] * m[:, 0]) / np.hypot(ab[:, 0], ab[:, 1])))


def plug_arcs(drive, po: dict, tol: float):
    """The plug's (generator ring's) outline as tangent arcs within ``tol`` (once: 1440 straight segments in the
    DXF where the README promised arcs): the same offset of the law's neutral line, fitted against the law itself."""
    law = drive.law_at(po["z_mm"]) if drive.coned else drive.law
    return fit_closed_curve(lambda t: deformed_curve(law, drive.r_m, po["offset_mm"], t), tol)


def _plug_data(drive, sizes, info: dict, what: str, radii, tol: float) -> DxfLayer:
    """The plug's data block: what a shop needs to make and check it (law, W0, diameters, the bearing it carries)."""
    d = drive.design
    z_g = info["generator_section_z_mm"]
    w0 = (drive.law_at(z_g) if drive.coned else drive.law).w0  # the law of the section the plug sits at
    r = float(np.max(radii))
    h = max(0.5, round(0.02 * 2 * r, 1))
    lines = [
        f"{what.upper()} DATA",
        f"{d.drive.name}",
        f"law: {d.generator.law}, W0 = {w0:.4f} mm at the generator section z = {z_g:g} mm",
        f"major diameter = {info['plug_major_diameter_mm']:.4f} mm, minor diameter = {info['plug_minor_diameter_mm']:.4f} mm",
        f"bearing: ring section {sizes.bearing_thickness:g} mm, width {sizes.bearing_width:g} mm",
        f"seat {info['seat_offset_from_neutral_mm']:+.4f} mm from the neutral line (CENTER line, not cut)",
        f"outline: tangent arcs within {tol * 1e3:g} um of the exact curve",
    ]
    texts = tuple((1.15 * r, r - 1.6 * h * k, h, line) for k, line in enumerate(lines))
    return DxfLayer(f"{what.upper().replace(' ', '_')}_DATA", texts=texts, color=7)


def _min_curvature_radius(pts: np.ndarray) -> float:
    """Smallest radius of the circle through three consecutive vertices of a closed polygon, mm."""
    a, b, c = np.roll(pts, 1, axis=0), pts, np.roll(pts, -1, axis=0)
    ab, bc, ca = np.hypot(*(b - a).T), np.hypot(*(c - b).T), np.hypot(*(a - c).T)
    cross = np.abs((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    with np.errstate(divide="ignore"):
        R = ab * bc * ca / (2.0 * cross)
    return float(R.min())


def plug(drive, sizes, tol: float) -> Part:
    """The wave-generator plug (internal deformation) or generator ring (external), with its bearing seat outline."""
    po = plug_outline(drive, sizes)
    outline, off = po["outline"], po["offset_mm"]
    width = sizes.bearing_width
    z0, z1 = po["z_mm"] - 0.5 * width, po["z_mm"] + 0.5 * width
    rho = _min_curvature_radius(po["neutral"])
    if not drive.external and -off >= rho:
        raise DesignError(
            "parts.bearing_thickness",
            f"the bearing ({sizes.bearing_thickness:g} mm) does not fit the plug: its seat lies "
            f"{-off:.3f} mm inside the neutral line, beyond the line's smallest radius of curvature {rho:.3f} mm",
        )
    if not shapely.LinearRing(outline).is_simple:
        raise DesignError(
            "parts.bearing_thickness",
            f"the bearing ({sizes.bearing_thickness:g} mm) does not fit the plug: its outline crosses itself",
        )
    radii = np.hypot(*outline.T)
    info = {
        "bearing_thickness_mm": sizes.bearing_thickness,
        "bearing_width_mm": width,
        "seat_offset_from_neutral_mm": off,
        "generator_section_z_mm": po["z_mm"],
        "neutral_min_curvature_radius_mm": rho,
        "plug_major_diameter_mm": 2 * float(radii.max()),
        "plug_minor_diameter_mm": 2 * float(radii.min()),
    }
    # the tangent arcs the drawing has, within the chord tolerance of the law's curve: the solid's outline too (planes
    # and cylinders, whose volume OpenCASCADE integrates exactly; a B-spline face's it integrates to ~1e-4 only)
    arcs = plug_arcs(drive, po, tol)
    area = abs(path_area(arcs))
    perim = float(np.sum(np.hypot(*(np.roll(outline, -1, axis=0) - outline).T)))
    if not drive.external:
        bore_d = (
            sizes.plug_bore_diameter if sizes.plug_bore_diameter is not None else round(0.4 * 2 * float(radii.min()), 1)
        )
        if 0.5 * bore_d >= 0.9 * float(radii.min()):
            raise DesignError(
                "parts.plug_bore_diameter",
                f"{bore_d:g} mm does not fit the plug (smallest plug diameter {2 * radii.min():.3f} mm, "
                f"wall at least a tenth of its radius)",
            )
        r_b = 0.5 * bore_d
        vol = (area - PI * r_b**2) * width
        info["plug_bore_diameter_mm"] = bore_d
        layers = [
            DxfLayer("PLUG", paths=(arcs,), color=2),
            DxfLayer("PLUG_BORE", circles=((0.0, 0.0, r_b),), color=2),
            DxfLayer("NEUTRAL_LINE", outlines=(po["neutral"],), color=3, construction=True),
            _plug_data(drive, sizes, info, "plug", radii, tol),
        ]
        name = "plug"
        body = prism(path_loop(arcs, outline, "seat"), [circle_loop(r_b, tol, "bore")], z0, z1)
        rmax = float(radii.max())
    else:
        R_out = float(radii.max()) + max(2.0, sizes.bearing_thickness)
        vol = (PI * R_out**2 - area) * width
        info["ring_outer_diameter_mm"] = 2 * R_out
        layers = [
            DxfLayer("GENERATOR_RING", paths=(arcs,), circles=((0.0, 0.0, R_out),), color=2),
            DxfLayer("NEUTRAL_LINE", outlines=(po["neutral"],), color=3, construction=True),
            _plug_data(drive, sizes, info, "generator ring", radii, tol),
        ]
        name = "generator_ring"
        body = prism(circle_loop(R_out, tol, "rim"), [path_loop(arcs, outline, "seat")], z0, z1)
        rmax = R_out
    info["volume_tol_mm3"] = tol * perim * width  # the arcs known to the chord tolerance along the whole outline
    info["plug_outline"] = outline
    info["neutral_line"] = po["neutral"]
    return Part(name, layers, {name: (body,)}, vol, ((-rmax, -rmax, z0), (rmax, rmax, z1)), info)


def _rigid_teeth(drive, style: str, tol: float, sectored: dict | None) -> tuple:
    """The rigid gear's toothed outline: ``(loop, area, DXF layer builder)``, of the design's gear or of the sectored
    one (its outline the polygon of its band)."""
    g = drive.rigid
    if sectored is None:
        path = fit_gear(g, tol)
        band = _band(g)
        return (
            path_loop(path, band, "teeth"),
            abs(path_area(path)),
            lambda: _teeth_layer("RIGID", g, path, style, 1, band),
        )
    if drive.external:
        raise DesignError("sectors", "a sectored rigid gear is built for internal deformation only")
    band = np.asarray(sectored["outline"], dtype=float)
    return polygon_loop(band, "teeth"), abs(signed_area(band)), lambda: DxfLayer("RIGID", outlines=(band,), color=1)


def rigid(drive, sizes, style: str, tol: float, sectored: dict | None = None) -> Part:
    """The rigid gear: internal teeth in a ring with a bolted mounting flange (internal deformation) or external teeth on a bolted hub.

    ``sectored`` (:func:`wgcad.sector.built.built_gear`):
    the sectored rigid gear of a design with ``[sectors]``, its teeth at the
    heights built, its outline the symmetric chord band of its curves.
    """
    g = drive.rigid
    bw = drive.design.drive.face_width
    teeth, area, teeth_layer = _rigid_teeth(drive, style, tol, sectored)
    R = drive.rigid_rim_radius
    dh = sizes.flange_bolt_hole_diameter
    holes = bolt_circle(
        sizes.flange_bolt_circle_diameter, sizes.flange_bolt_count, dh, phase=PI / sizes.flange_bolt_count
    )
    hole_circles = tuple((x, y, 0.5 * h) for x, y, h in holes)
    hole_area = len(holes) * PI * (0.5 * dh) ** 2
    tf = sizes.flange_thickness
    info = {
        "bolt_circle_diameter_mm": sizes.flange_bolt_circle_diameter,
        "bolt_count": sizes.flange_bolt_count,
        "bolt_hole_diameter_mm": dh,
    }
    if not drive.external:
        Rf = 0.5 * sizes.flange_outer_diameter
        tip_r = Rf
        vol = (PI * R * R - area) * (bw - tf) + (PI * Rf * Rf - area - hole_area) * tf
        gl, data, _ = data_layer("rigid", g, tol, 1.15 * Rf, Rf, max(0.5, round(0.02 * 2 * R, 1)), sectored=sectored)
        layers = [
            teeth_layer(),
            DxfLayer("RIGID_OUTER", circles=((0.0, 0.0, R),), color=1),
            DxfLayer("FLANGE", circles=((0.0, 0.0, Rf),), color=1),
            DxfLayer("FLANGE_BOLT_HOLES", circles=hole_circles, color=3),
            gl,
        ]
        kind = "rigid gear with mounting flange"
        if sectored is not None:
            kind = f"sectored rigid gear with mounting flange ({sectored['mode']} tooth heights)"
        info.update({"kind": kind, "flange_outer_diameter_mm": 2 * Rf, "flange_thickness_mm": tf})
        body = _flanged(teeth, R, Rf, [circle_loop(0.5 * h, tol, "bolt_holes", x, y) for x, y, h in holes], bw, tf, tol)
    else:
        tip_r = float(np.hypot(*g.outline.T).max())
        vol = (area - PI * R * R - hole_area) * bw
        gl, data, _ = data_layer("rigid", g, tol, 1.15 * tip_r, tip_r, max(0.5, round(0.02 * 2 * tip_r, 1)))
        layers = [
            teeth_layer(),
            DxfLayer("RIGID_BORE", circles=((0.0, 0.0, R),), color=1),
            DxfLayer("BOLT_HOLES", circles=hole_circles, color=3),
            gl,
        ]
        info["kind"] = "rigid gear (external teeth) with bolted hub"
        bolts = [circle_loop(0.5 * h, tol, "bolt_holes", x, y) for x, y, h in holes]
        body = prism(teeth, [circle_loop(R, tol, "bore"), *bolts], 0.0, bw)
    info["gear_data"] = data
    return Part("rigid", layers, {"rigid": (body,)}, vol, ((-tip_r, -tip_r, 0.0), (tip_r, tip_r, bw)), info)


def _flanged(teeth, R: float, Rf: float, bolts: list, bw: float, tf: float, tol: float) -> Body:
    """The internal rigid gear's body: teeth inside a ring of radius ``R`` over ``0 <= z <= bw - tf`` and the flange
    of radius ``Rf`` with its bolt holes over ``bw - tf <= z <= bw``; one tooth face runs the whole width."""
    reach = float(np.hypot(*teeth.polygon.T).max())
    if not reach < min(R, Rf) - MARGIN:
        raise DesignError("parts.flange_outer_diameter", f"the teeth reach radius {reach:.4f} mm, the rim {R:.4f} mm")
    flange = circle_loop(Rf, tol, "flange")
    if tf >= bw:
        return prism(flange, [teeth, *bolts], 0.0, bw)
    if not Rf > R + MARGIN:
        raise DesignError("parts.flange_outer_diameter", f"{2 * Rf:g} mm must exceed the rim's {2 * R:.4f} mm")
    _holes_fit([(*b.vertices[0], 2 * b.radius) for b in bolts], R, Rf, "parts.flange_bolt_circle_diameter")
    zs = bw - tf
    walls = (
        Wall(teeth, 0.0, bw, False),
        Wall(circle_loop(R, tol, "rim"), 0.0, zs, True),
        Wall(flange, zs, bw, True),
        *(Wall(b, zs, bw, False) for b in bolts),
    )
    holes = tuple((i, False) for i in range(3, len(walls)))
    return Body(
        walls,
        (
            Cap(0.0, False, ((1, True), (0, False)), "end"),
            Cap(zs, False, ((2, True), (1, False), *holes), "flange_face"),
            Cap(bw, True, ((2, True), (0, False), *holes), "end"),
        ),
    )
