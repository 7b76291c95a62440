"""STEP AP214 B-rep solids bounded by vertical walls and horizontal faces, written as text (no CAD kernel).

Every solid of the part set is of this kind: toothed rings, the cup on its
ring, the flanged rigid gear, the plug. Such a solid is a set of *walls* - a
closed loop of plane curves (lines, circular arcs, circles, a periodic cubic
B-spline) swept straight along z between two heights, or ruled between two
loops of corresponding segments (the face-modified ring, docs/models.md
13.4) - and *caps*, the plane faces at the walls' ends. Its
boundary follows from the loops alone: no surface is intersected with
another, so no boolean operation is needed and OpenCASCADE (235 MB resident
once imported, docs/models.md appendix A) is not loaded for them.

Orientation rules (ISO 10303-42): a face's bounds run counter-clockwise
seen from outside the solid. A wall's loop is given with the material on its
left seen from +z (outer boundaries counter-clockwise, holes clockwise); its
side faces then run along the bottom edge, up the end's vertical edge, back
along the top edge and down the start's, and the outward normal lies to the
right of the loop. Before the text is written every edge is checked to be
used by exactly two faces in opposite directions (a closed, oriented shell).
"""

from __future__ import annotations

import math

import numpy as np

from wgcad.errors import GeometryError
from wgcad.export.arcs import bulge_centres
from wgcad.plane import signed_area

__all__ = [
    "Line",
    "Arc",
    "Circle",
    "Spline",
    "path_loop",
    "polygon_loop",
    "circle_loop",
    "spline_loop",
    "Brep",
    "prism",
    "real",
]

#: FILE_NAME time stamp, fixed so the same design gives byte-identical files (wgcad.export.step stamps OCCT's too)
FIXED_STAMP = "2000-01-01T00:00:00"


def real(x: float) -> str:
    """A STEP real: always with a decimal point (``1.``, ``-0.5``, ``1.5E-07``)."""
    r = repr(float(x))
    if "e" in r:
        mant, exp = r.split("e")
        if "." not in mant:
            mant += "."
        return f"{mant}E{exp}"
    return r[:-1] if r.endswith(".0") else r


class Line:
    """A straight segment ``p0 -> p1`` (mm)."""

    closed = False

    def __init__(self, p0, p1):
        self.p0, self.p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
        d = self.p1 - self.p0
        self.length = float(np.hypot(*d))
        if not self.length > 0:
            raise GeometryError("a straight segment of zero length")
        self.dir = d / self.length


class Arc:
    """A circular arc ``p0 -> p1`` about ``center`` through the signed angle ``theta`` (counter-clockwise if > 0)."""

    closed = False

    def __init__(self, p0, p1, center, theta: float):
        self.p0, self.p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
        self.center = np.asarray(center, dtype=float)
        self.radius = float(np.hypot(*(self.p0 - self.center)))
        self.theta = float(theta)
        self.ccw = self.theta > 0


class Circle:
    """A whole circle, started at ``center + (r, 0)``, counter-clockwise if ``ccw``."""

    closed = True

    def __init__(self, center, radius: float, ccw: bool):
        self.center = np.asarray(center, dtype=float)
        self.radius = float(radius)
        self.ccw = bool(ccw)
        self.p0 = self.p1 = self.center + (self.radius, 0.0)


class Spline:
    """A closed cubic B-spline: knots (with repeats allowed), plane control points; runs with its parameter."""

    closed = True

    def __init__(self, knots, control, degree: int, start):
        self.knots = np.asarray(knots, dtype=float)
        self.control = np.asarray(control, dtype=float)
        self.degree = int(degree)
        self.p0 = self.p1 = np.asarray(start, dtype=float)


def path_loop(vertices, bulges, material_left: bool = True) -> list:
    """Segments of a closed path of lines and arcs (``bulge = tan(theta / 4)``, 0 for a line), oriented so that the
    material lies on their left (``material_left``) seen from +z: an outer boundary is made counter-clockwise, a hole
    clockwise (pass ``material_left=False`` for a hole)."""
    v = np.asarray(vertices, dtype=float)
    b = np.asarray(bulges, dtype=float)
    if (signed_area(v) > 0) != material_left:
        v, b = v[::-1], -np.roll(b[::-1], -1)
    e = np.roll(v, -1, axis=0)
    centre, _, theta = bulge_centres(v, e, b)
    return [Line(v[i], e[i]) if b[i] == 0.0 else Arc(v[i], e[i], centre[i], theta[i]) for i in range(len(v))]


def polygon_loop(points, material_left: bool = True) -> list:
    """Straight segments of a closed polygon (closing edge implicit), oriented as :func:`path_loop`."""
    pts = np.asarray(points, dtype=float)
    return path_loop(pts, np.zeros(len(pts)), material_left)


def circle_loop(cx: float, cy: float, r: float, material_left: bool = True) -> list:
    """One whole circle: counter-clockwise around material inside, clockwise around a hole."""
    return [Circle((cx, cy), r, material_left)]


def spline_loop(points, material_left: bool = True) -> list:
    """The periodic cubic B-spline through closed ``points`` (closing point implicit), chord-length parameters (as
    OpenCASCADE's ``GeomAPI_Interpolate``), oriented as :func:`path_loop`."""
    from scipy.interpolate import make_interp_spline

    pts = np.asarray(points, dtype=float)
    if (signed_area(pts) > 0) != material_left:
        pts = pts[::-1]
    closed = np.vstack([pts, pts[:1]])
    t = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(closed, axis=0).T))])
    spl = make_interp_spline(t, closed, k=3, bc_type="periodic")
    return [Spline(spl.t, spl.c, 3, pts[0])]


def _bezier(seg) -> tuple[np.ndarray, np.ndarray]:
    """A segment as one rational Bezier piece: control points and weights (an arc under half a turn: the tangents'
    meeting point in the middle, weighted ``cos(theta / 2)``)."""
    if isinstance(seg, Line):
        return np.array([seg.p0, seg.p1]), np.array([1.0, 1.0])
    a0 = np.arctan2(*(seg.p0 - seg.center)[::-1])
    theta = seg.theta
    if not abs(theta) < np.pi:
        raise GeometryError("an arc of half a turn or more in a ruled face")
    mid = a0 + 0.5 * theta
    half = math.cos(0.5 * theta)
    pm = seg.center + seg.radius / half * np.array([math.cos(mid), math.sin(mid)])
    return np.array([seg.p0, pm, seg.p1]), np.array([1.0, half, 1.0])


class _Wall:
    def __init__(self, loop, z0, z1, bottom, top):
        self.loop, self.z0, self.z1, self.bottom, self.top = loop, z0, z1, bottom, top


class Brep:
    """One solid as STEP text: add walls, then the caps that close them, then :meth:`text`."""

    def __init__(self):
        self.lines: list[str] = []
        self.faces: list[int] = []
        self._uses: dict[int, int] = {}
        self._count: dict[int, int] = {}
        self._dirs: dict[tuple, int] = {}

    # -- entities ---------------------------------------------------------------------------------------------------
    def _add(self, text: str) -> int:
        self.lines.append(text)
        return len(self.lines)

    def _point(self, x, y, z) -> int:
        return self._add(f"CARTESIAN_POINT('',({real(x)},{real(y)},{real(z)}))")

    def _dir(self, x, y, z) -> int:
        key = (float(x), float(y), float(z))
        if key not in self._dirs:
            self._dirs[key] = self._add(f"DIRECTION('',({real(x)},{real(y)},{real(z)}))")
        return self._dirs[key]

    def _axis(self, origin, axis=(0.0, 0.0, 1.0), ref=(1.0, 0.0, 0.0)) -> int:
        return self._add(f"AXIS2_PLACEMENT_3D('',#{self._point(*origin)},#{self._dir(*axis)},#{self._dir(*ref)})")

    def _vertex(self, x, y, z) -> int:
        return self._add(f"VERTEX_POINT('',#{self._point(x, y, z)})")

    def _edge(self, v0: int, v1: int, curve: int, sense: bool) -> int:
        return self._add(f"EDGE_CURVE('',#{v0},#{v1},#{curve},{'.T.' if sense else '.F.'})")

    def _line(self, p, d) -> int:
        vec = self._add(f"VECTOR('',#{self._dir(*d)},1.)")
        return self._add(f"LINE('',#{self._point(*p)},#{vec})")

    def _circle(self, center, z, r, ref=(1.0, 0.0)) -> int:
        return self._add(f"CIRCLE('',#{self._axis((center[0], center[1], z), ref=(ref[0], ref[1], 0.0))},{real(r)})")

    def _spline(self, seg: Spline, z: float) -> int:
        pts = ",".join(f"#{self._point(x, y, z)}" for x, y in seg.control)
        knots, mults = np.unique(seg.knots, return_counts=True)
        return self._add(
            f"B_SPLINE_CURVE_WITH_KNOTS('',{seg.degree},({pts}),.UNSPECIFIED.,.T.,.F.,"
            f"({','.join(str(int(m)) for m in mults)}),({','.join(real(k) for k in knots)}),.UNSPECIFIED.)"
        )

    def _curve(self, seg, z) -> tuple[int, bool]:
        """The 3D curve of a segment at height z, and whether the segment runs with its parameter."""
        if isinstance(seg, Line):
            return self._line((seg.p0[0], seg.p0[1], z), (seg.dir[0], seg.dir[1], 0.0)), True
        if isinstance(seg, Arc):
            ref = (seg.p0 - seg.center) / seg.radius
            return self._circle(seg.center, z, seg.radius, ref), seg.ccw
        if isinstance(seg, Circle):
            return self._circle(seg.center, z, seg.radius), seg.ccw
        return self._spline(seg, z), True

    def _surface(self, seg, z0: float, z1: float) -> tuple[int, bool]:
        """The side surface of a segment swept from z0 to z1, and whether its normal points out of the material."""
        if isinstance(seg, Line):
            n = (seg.dir[1], -seg.dir[0], 0.0)  # right of the segment: out of the material
            axis = self._axis((seg.p0[0], seg.p0[1], z0), n, (seg.dir[0], seg.dir[1], 0.0))
            return self._add(f"PLANE('',#{axis})"), True
        if isinstance(seg, (Arc, Circle)):
            axis = self._axis((seg.center[0], seg.center[1], z0))
            return self._add(f"CYLINDRICAL_SURFACE('',#{axis},{real(seg.radius)})"), seg.ccw
        curve, _ = self._curve(seg, z0)
        vec = self._add(f"VECTOR('',#{self._dir(0.0, 0.0, 1.0)},{real(z1 - z0)})")
        return self._add(f"SURFACE_OF_LINEAR_EXTRUSION('',#{curve},#{vec})"), True

    def _face(self, bounds: list, surface: int, sense: bool) -> None:
        """bounds: [(oriented edges [(edge, forward)], orientation)]."""
        ids = []
        for edges, orient in bounds:
            oe = []
            for e, fwd in edges:
                oe.append(self._add(f"ORIENTED_EDGE('',*,*,#{e},{'.T.' if fwd else '.F.'})"))
                self._uses[e] = self._uses.get(e, 0) + (1 if fwd == orient else -1)
                self._count[e] = self._count.get(e, 0) + 1
            loop = self._add(f"EDGE_LOOP('',({','.join(f'#{i}' for i in oe)}))")
            ids.append(self._add(f"FACE_BOUND('',#{loop},{'.T.' if orient else '.F.'})"))
        self.faces.append(
            self._add(f"ADVANCED_FACE('',({','.join(f'#{i}' for i in ids)}),#{surface},{'.T.' if sense else '.F.'})")
        )

    # -- the solid --------------------------------------------------------------------------------------------------
    def wall(self, loop: list, z0: float, z1: float) -> _Wall:
        """The side faces of a loop (material on its left seen from +z) swept from ``z0`` up to ``z1``."""
        if not z1 > z0:
            raise GeometryError(f"a wall from z = {z0} to {z1} mm")
        if len(loop) > 1 and any(s.closed for s in loop):
            raise GeometryError("a closed curve must be a loop of its own")
        n = len(loop)
        joints = [s.p0 for s in loop]
        vb = [self._vertex(p[0], p[1], z0) for p in joints]
        vt = [self._vertex(p[0], p[1], z1) for p in joints]
        up = [self._edge(vb[i], vt[i], self._line((*joints[i], z0), (0.0, 0.0, 1.0)), True) for i in range(n)]
        bottom, top = [], []
        for i, seg in enumerate(loop):
            j = (i + 1) % n
            curve, sense = self._curve(seg, z0)
            bottom.append(self._edge(vb[i], vb[j], curve, sense))
            curve, sense = self._curve(seg, z1)
            top.append(self._edge(vt[i], vt[j], curve, sense))
            surface, out = self._surface(seg, z0, z1)
            self._face([([(bottom[i], True), (up[j], True), (top[i], False), (up[i], False)], True)], surface, out)
        return _Wall(loop, z0, z1, bottom, top)

    def ruled_wall(self, bottom: list, top: list, z0: float, z1: float) -> _Wall:
        """The side faces ruled between two loops of corresponding segments, ``bottom`` at ``z0`` and ``top`` at
        ``z1`` (both with the material on their left; segment ``i`` of one joined to segment ``i`` of the other by
        straight lines between points of equal parameter, as a ruled loft).

        A pair of segments that are translates of each other sweeps an oblique cylinder (a surface of linear
        extrusion) or a plane; any other pair of arcs of one angle, or of lines, a rational B-spline surface of
        degree 1 across and 2 (1 for lines) along, which is that ruled surface exactly.
        """
        if not z1 > z0:
            raise GeometryError(f"a wall from z = {z0} to {z1} mm")
        if len(bottom) != len(top) or any(type(a) is not type(b) or a.closed for a, b in zip(bottom, top)):
            raise GeometryError("a ruled wall needs loops of corresponding open segments of the same kinds")
        n = len(bottom)
        vb = [self._vertex(s.p0[0], s.p0[1], z0) for s in bottom]
        vt = [self._vertex(s.p0[0], s.p0[1], z1) for s in top]
        side = []
        for i in range(n):
            a, b = np.array([*bottom[i].p0, z0]), np.array([*top[i].p0, z1])
            d = (b - a) / np.linalg.norm(b - a)
            side.append(self._edge(vb[i], vt[i], self._line(a, d), True))
        out_b, out_t = [], []
        for i, (sa, sb) in enumerate(zip(bottom, top)):
            j = (i + 1) % n
            curve, sense = self._curve(sa, z0)
            out_b.append(self._edge(vb[i], vb[j], curve, sense))
            out_t.append(self._edge(vt[i], vt[j], self._curve(sb, z1)[0], sense))
            surface, outward = self._ruled(sa, sb, z0, z1, curve)
            self._face(
                [([(out_b[i], True), (side[j], True), (out_t[i], False), (side[i], False)], True)], surface, outward
            )
        return _Wall(bottom, z0, z1, out_b, out_t)

    def _ruled(self, sa, sb, z0: float, z1: float, curve_a: int) -> tuple[int, bool]:
        """The surface ruled between corresponding segments, and whether its normal points out of the material."""
        shift = sb.p0 - sa.p0
        vec = np.array([shift[0], shift[1], z1 - z0])
        # translates within 1e-9 mm (the same curve moved: rounding of ~1e-13 mm), far inside the file's 1e-7 mm
        translated = np.allclose(sb.p1 - sa.p1, shift, rtol=0, atol=1e-9) and (
            isinstance(sa, Line) or (np.allclose(sb.center - sa.center, shift, rtol=0, atol=1e-9))
        )
        if translated and isinstance(sa, Line):
            n = np.cross([sa.dir[0], sa.dir[1], 0.0], vec)
            n /= np.linalg.norm(n)
            axis = self._axis((sa.p0[0], sa.p0[1], z0), tuple(n), (sa.dir[0], sa.dir[1], 0.0))
            return self._add(f"PLANE('',#{axis})"), True
        if translated:
            length = float(np.linalg.norm(vec))
            v = self._add(f"VECTOR('',#{self._dir(*(vec / length))},{real(length)})")
            # normal C'(u) x V: right of the circle's counter-clockwise run, out of the material where the arc runs so
            return self._add(f"SURFACE_OF_LINEAR_EXTRUSION('',#{curve_a},#{v})"), sa.ccw
        rows, w = [], None
        for seg, z in ((sa, z0), (sb, z1)):
            pts, wts = _bezier(seg)
            if w is not None and not np.allclose(wts, w, rtol=0, atol=1e-12):
                raise GeometryError("a ruled face between arcs of different angles")
            w = wts
            rows.append([(x, y, z) for x, y in pts])
        net = ",".join("(" + ",".join(f"#{self._point(*p)}" for p in row) + ")" for row in rows)
        deg = len(w) - 1
        knots = f"(2,2),({deg + 1},{deg + 1}),(0.,1.),(0.,1.),.UNSPECIFIED."
        if deg == 1:
            surf = self._add(f"B_SPLINE_SURFACE_WITH_KNOTS('',1,1,({net}),.UNSPECIFIED.,.F.,.F.,.F.,{knots})")
        else:
            weights = "(" + ",".join("(" + ",".join(real(x) for x in w) + ")" for _ in rows) + ")"
            surf = self._add(
                f"( BOUNDED_SURFACE() B_SPLINE_SURFACE(1,{deg},({net}),.UNSPECIFIED.,.F.,.F.,.F.) "
                f"B_SPLINE_SURFACE_WITH_KNOTS({knots}) GEOMETRIC_REPRESENTATION_ITEM() "
                f"RATIONAL_B_SPLINE_SURFACE({weights}) REPRESENTATION_ITEM('') SURFACE() )"
            )
        # S_u (across, up the ruling) x S_v (along the segment's run): left of the run for a rising ruling, so the
        # normal points into the material; the face's normal is the opposite one
        return surf, False

    def cap(self, z: float, up: bool, parts: list) -> None:
        """The plane face at height ``z``, its outward normal +z if ``up``.

        ``parts``: ``(wall, region_left)`` per loop bounding it, the wall ending or starting at ``z``;
        ``region_left``: the face lies on the left of the wall's loop (where the wall's material is).
        """
        bounds = []
        for wall, region_left in parts:
            if z == wall.z1:
                edges = wall.top
            elif z == wall.z0:
                edges = wall.bottom
            else:
                raise GeometryError(f"a cap at z = {z} mm on a wall from {wall.z0} to {wall.z1} mm")
            bounds.append(([(e, True) for e in edges], region_left == up))
        plane = self._add(f"PLANE('',#{self._axis((0.0, 0.0, z))})")
        self._face(bounds, plane, up)

    def check(self) -> None:
        """Every edge in exactly two faces, once each way (a closed shell, oriented alike)."""
        bad = [e for e in self._count if self._count[e] != 2 or self._uses[e] != 0]
        if bad:
            raise GeometryError(f"{len(bad)} edges of the solid are not shared by two faces running opposite ways")

    def text(self, name: str) -> str:
        """The whole STEP file (AP214, mm) of this one solid, named ``name``."""
        self.check()
        body = list(self.lines)

        def add(t: str) -> int:
            body.append(t)
            return len(body)

        shell = add(f"CLOSED_SHELL('',({','.join(f'#{f}' for f in self.faces)}))")
        brep = add(f"MANIFOLD_SOLID_BREP('{name}',#{shell})")
        length = add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
        angle = add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
        solid_angle = add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
        unc = add(
            f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#{length},'distance_accuracy_value',"
            "'confusion accuracy')"
        )
        ctx = add(
            f"( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc})) "
            f"GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{solid_angle})) REPRESENTATION_CONTEXT"
            "('Context #1','3D Context with UNIT and UNCERTAINTY') )"
        )
        origin = add("CARTESIAN_POINT('',(0.,0.,0.))")
        z_dir = add("DIRECTION('',(0.,0.,1.))")
        x_dir = add("DIRECTION('',(1.,0.,0.))")
        place = add(f"AXIS2_PLACEMENT_3D('',#{origin},#{z_dir},#{x_dir})")
        rep = add(f"ADVANCED_BREP_SHAPE_REPRESENTATION('',(#{place},#{brep}),#{ctx})")
        app = add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
        add(f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})")
        pctx = add(f"PRODUCT_CONTEXT('',#{app},'mechanical')")
        product = add(f"PRODUCT('{name}','{name}','',(#{pctx}))")
        formation = add(f"PRODUCT_DEFINITION_FORMATION('','',#{product})")
        dctx = add(f"PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')")
        definition = add(f"PRODUCT_DEFINITION('design','',#{formation},#{dctx})")
        shape = add(f"PRODUCT_DEFINITION_SHAPE('','',#{definition})")
        add(f"SHAPE_DEFINITION_REPRESENTATION(#{shape},#{rep})")
        add(f"PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{product}))")
        head = (
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('wgcad part'),'2;1');\n"
            f"FILE_NAME('{name}','{FIXED_STAMP}',(''),(''),'wgcad','wgcad','');\n"
            "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
        )
        data = "".join(f"#{i} = {t};\n" for i, t in enumerate(body, start=1))
        return head + data + "ENDSEC;\nEND-ISO-10303-21;\n"


def prism(outer: list, holes: list, z0: float, z1: float) -> Brep:
    """The solid between ``z0`` and ``z1`` over a region: its outer loop and hole loops (each oriented with the
    material on its left, as the ``*_loop`` functions make them)."""
    b = Brep()
    walls = [b.wall(loop, z0, z1) for loop in [outer, *holes]]
    b.cap(z1, True, [(w, True) for w in walls])
    b.cap(z0, False, [(w, True) for w in walls])
    return b
