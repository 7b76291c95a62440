"""STEP export of extruded and turned solids through OpenCASCADE (OCP): B-rep faces from exact arcs, read-back checks, in mm."""

from __future__ import annotations

import os
import re

import numpy as np

from wgcad.atomic import atomic_write
from wgcad.errors import GeometryError
from wgcad.export.brep import FIXED_STAMP  # the fixed FILE_NAME time stamp: byte-identical files

__all__ = [
    "wire_from_path",
    "wire_from_polygon",
    "bspline_wire",
    "circle_wire",
    "prism",
    "revolve_profile",
    "fuse",
    "cut",
    "drill",
    "write_step",
    "read_step",
    "solid_props",
    "step_text",
]


def _pnt(x, y, z=0.0):
    from OCP.gp import gp_Pnt

    return gp_Pnt(float(x), float(y), float(z))


def wire_from_path(vertices, bulges, z: float = 0.0):
    """A closed OCP wire of arcs (non-zero bulge) and lines (zero bulge) in the plane ``z`` (default 0).

    Parameters
    ----------
    vertices : (n, 2) float
        Segment starts, mm; segment ``i`` ends at vertex ``i + 1`` (closing).
    bulges : (n,) float
        ``tan(theta / 4)`` of each segment (see :mod:`wgcad.export.arcs`).

    Returns
    -------
    OCP.TopoDS.TopoDS_Wire
    """
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.TopoDS import TopoDS_Wire

    from wgcad.export.arcs import arc_points

    v = np.asarray(vertices, dtype=float)
    b = np.asarray(bulges, dtype=float)
    e = np.roll(v, -1, axis=0)
    mid = arc_points(v, e, b, 3)[:, 1, :]
    verts = [BRepBuilderAPI_MakeVertex(_pnt(p[0], p[1], z)).Vertex() for p in v]
    # BRepBuilderAPI_MakeWire searches the wire for shared vertices on every
    # Add (quadratic: 4 s for 774 edges); the edges already share vertices,
    # so the plain builder is enough (50 ms).
    wire = TopoDS_Wire()
    bld = BRep_Builder()
    bld.MakeWire(wire)
    n = len(v)
    for i in range(n):
        v0, v1 = verts[i], verts[(i + 1) % n]
        if b[i] == 0.0:
            mk = BRepBuilderAPI_MakeEdge(v0, v1)
        else:
            arc = GC_MakeArcOfCircle(_pnt(*v[i], z), _pnt(*mid[i], z), _pnt(*e[i], z)).Value()
            mk = BRepBuilderAPI_MakeEdge(arc, v0, v1)
        if not mk.IsDone():
            raise GeometryError(f"segment {i} of a closed path is degenerate")
        bld.Add(wire, mk.Edge())
    wire.Closed(True)
    return wire


def wire_from_polygon(points):
    """A closed OCP polygon wire through ``points (n, 2)`` (closing edge implicit)."""
    pts = np.asarray(points, dtype=float)
    return wire_from_path(pts, np.zeros(len(pts)))


def bspline_wire(points):
    """A closed wire of one smooth periodic B-spline interpolating ``points (n, 2)`` (closing point implicit)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.collections import HArray1_gp_Pnt as TColgp_HArray1OfPnt
    from OCP.GeomAPI import GeomAPI_Interpolate
    from OCP.TopoDS import TopoDS_Wire

    pts = np.asarray(points, dtype=float)
    arr = TColgp_HArray1OfPnt(1, len(pts))
    for i, p in enumerate(pts):
        arr.SetValue(i + 1, _pnt(*p))
    interp = GeomAPI_Interpolate(arr, True, 1e-9)
    interp.Perform()
    if not interp.IsDone():
        raise GeometryError("B-spline interpolation of a closed outline failed")
    wire = TopoDS_Wire()
    bld = BRep_Builder()
    bld.MakeWire(wire)
    bld.Add(wire, BRepBuilderAPI_MakeEdge(interp.Curve()).Edge())
    wire.Closed(True)
    return wire


def circle_wire(radius: float, cx: float = 0.0, cy: float = 0.0):
    """A closed circular wire (one exact circle edge)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir

    circ = gp_Circ(gp_Ax2(_pnt(cx, cy), gp_Dir(0.0, 0.0, 1.0)), float(radius))
    return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circ).Edge()).Wire()


def prism(outer, holes=(), height: float = 1.0, z0: float = 0.0):
    """Extrude a planar region (outer wire, hole wires) along +z from ``z0`` by ``height`` into a solid.

    Wires are oriented here (outer counter-clockwise, holes clockwise, as seen
    from +z) so the caller need not care.
    """
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Transform
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Dir, gp_Pln, gp_Trsf, gp_Vec
    from OCP.ShapeFix import ShapeFix_Face

    mf = BRepBuilderAPI_MakeFace(gp_Pln(_pnt(0, 0, 0), gp_Dir(0, 0, 1)), outer, True)
    for h in holes:
        mf.Add(h)
    if not mf.IsDone():
        raise GeometryError("planar face of the outline could not be built")
    fix = ShapeFix_Face(mf.Face())
    fix.FixOrientation()
    fix.Perform()
    face = fix.Face()
    solid = BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, float(height))).Shape()
    if z0:
        t = gp_Trsf()
        t.SetTranslation(gp_Vec(0.0, 0.0, float(z0)))
        solid = BRepBuilderAPI_Transform(solid, t, True).Shape()
    return solid


def loft(wires):
    """A solid lofted through closed wires (bottom to top) by ruled faces between their corresponding edges.

    The wires must have the same number of edges in the same order (sections of one outline whose parts move
    linearly along the loft: then the ruled faces are the exact surfaces, docs/models.md 13.4).
    """
    from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections

    mk = BRepOffsetAPI_ThruSections(True, True, 1e-6)
    mk.CheckCompatibility(False)  # the edges already correspond one to one
    for w in wires:
        mk.AddWire(w)
    mk.Build()
    if not mk.IsDone():
        raise GeometryError("loft of the face-modified outline failed")
    return mk.Shape()


def cylinder(radius: float, z0: float, z1: float):
    """A solid cylinder about the z axis from ``z0`` to ``z1``."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir

    return BRepPrimAPI_MakeCylinder(gp_Ax2(_pnt(0.0, 0.0, z0), gp_Dir(0, 0, 1)), float(radius), float(z1 - z0)).Shape()


def revolve_profile(rz):
    """Solid of revolution about the z axis of a closed polygon in the (r, z) half-plane ``(n, 2)``, r >= 0."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.gp import gp_Ax1, gp_Dir

    rz = np.asarray(rz, dtype=float)
    xz = np.column_stack([rz[:, 0], np.zeros(len(rz)), rz[:, 1]])
    poly = BRepBuilderAPI_MakePolygon()
    for p in xz:
        poly.Add(_pnt(*p))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
    return BRepPrimAPI_MakeRevol(face, gp_Ax1(_pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2 * np.pi).Shape()


def fuse(a, b, touching: bool = False):
    """Boolean union of two shapes.

    ``touching``: the shapes only touch (faces in common, no common volume);
    OCCT's glue mode then skips the face-face intersections (the cup onto the
    toothed ring: 1.0 -> 0.8 s and 14 MB less on D1, the same solid).
    """
    from OCP.BOPAlgo import BOPAlgo_GlueShift
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse

    op = BRepAlgoAPI_Fuse()
    if touching:
        op.SetGlue(BOPAlgo_GlueShift)
    _run(op, a, b)
    if not op.IsDone():
        raise GeometryError("solid union failed")
    return op.Shape()


def cut(a, b):
    """Boolean difference ``a - b``."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    op = BRepAlgoAPI_Cut()
    _run(op, a, b)
    if not op.IsDone():
        raise GeometryError("solid difference failed")
    return op.Shape()


def _run(op, a, b) -> None:
    """Run a boolean on both cores (OCCT's parallel mode)."""
    from OCP.collections import List_TopoDS_Shape as TopTools_ListOfShape

    args, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
    args.Append(a)
    tools.Append(b)
    op.SetArguments(args)
    op.SetTools(tools)
    op.SetRunParallel(True)
    op.Build()


def drill(solid, holes, z0: float, z1: float):
    """Cut axial through-holes ``[(cx, cy, d), ...]`` between ``z0`` and ``z1`` from a solid."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir
    from OCP.TopoDS import TopoDS_Compound

    if not holes:
        return solid
    comp = TopoDS_Compound()
    bld = BRep_Builder()
    bld.MakeCompound(comp)
    for cx, cy, d in holes:
        cyl = BRepPrimAPI_MakeCylinder(
            gp_Ax2(_pnt(cx, cy, z0 - 1.0), gp_Dir(0, 0, 1)), d / 2.0, (z1 - z0) + 2.0
        ).Shape()
        bld.Add(comp, cyl)
    return cut(solid, comp)


def step_text(shapes: dict, name: str = "wgcad") -> str:
    """The STEP AP214 text of named solids ``{name: shape}`` in mm, with a fixed time stamp."""
    import tempfile

    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    _quiet()
    # the writer first: its constructor loads the STEP controller, and a static set before that does not exist
    # yet (SetCVal_s returns False, silently)
    w = STEPControl_Writer()
    for key, val in (("write.step.unit", "MM"), ("write.step.schema", "AP214IS"), ("write.step.product.name", name)):
        if not Interface_Static.SetCVal_s(key, val):
            raise GeometryError(f"OpenCASCADE has no STEP setting {key}")
    # no 2D parameter curves of the edges on their faces (pcurves): every edge is written as its 3D curve,
    # which is the geometry; readers rebuild pcurves as they load. On D1's part set this is 16.7 -> 6.6 MB
    # and 1.8 -> 1.1 s, and OCP and FreeCAD read back the same valid solids (tests/test_parts.py)
    if not Interface_Static.SetIVal_s("write.surfacecurve.mode", 0):
        raise GeometryError("OpenCASCADE has no STEP setting write.surfacecurve.mode")
    for part, shape in shapes.items():
        Interface_Static.SetCVal_s("write.step.product.name", part)
        if w.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone:
            raise GeometryError(f"STEP transfer of {part} failed")
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "out.step")
        if w.Write(path) != IFSelect_RetDone:
            raise GeometryError("STEP writer failed")
        with open(path, encoding="latin-1") as f:
            text = f.read()
    # the header's FILE_NAME carries the wall-clock time: fix it (reproducible output)
    text = re.sub(r"(FILE_NAME\('[^']*',)'[^']*'", rf"\1'{FIXED_STAMP}'", text, count=1)
    # OCCT numbers products by how many were written in this process ('rigid 3'): drop the counter
    return re.sub(r"PRODUCT\('([^']*?) \d+','\1 \d+'", r"PRODUCT('\1','\1'", text)


def _quiet() -> None:
    """Stop OpenCASCADE printing transfer statistics on stdout (the CLI's stdout is for its own output)."""
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


def write_step(path: str | os.PathLike, shapes: dict) -> None:
    """Write named solids ``{name: shape}`` to one STEP file, atomically."""
    text = step_text(shapes)
    atomic_write(path, text.encode("latin-1"))


def read_step(path: str | os.PathLike) -> list:
    """Read a STEP file back: its solids, in file order.

    Raises
    ------
    GeometryError
        If the file cannot be read.
    """
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    _quiet()
    r = STEPControl_Reader()
    if r.ReadFile(str(path)) != IFSelect_RetDone:
        raise GeometryError(f"{path}: not a readable STEP file")
    r.TransferRoots()
    shape = r.OneShape()
    out = []
    ex = TopExp_Explorer(shape, TopAbs_SOLID)
    while ex.More():
        out.append(TopoDS.Solid(ex.Current()))
        ex.Next()
    return out


def solid_props(shape) -> dict:
    """Validity, volume (mm^3), bounding box ``((x0, y0, z0), (x1, y1, z1))`` and face counts by surface type."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    box = Bnd_Box()
    box.SetGap(0.0)
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    x0, y0, z0, x1, y1, z1 = lo.X(), lo.Y(), lo.Z(), hi.X(), hi.Y(), hi.Z()
    kinds: dict = {}
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        k = str(BRepAdaptor_Surface(TopoDS.Face(ex.Current())).GetType()).split(".")[-1]
        kinds[k] = kinds.get(k, 0) + 1
        ex.Next()
    return {
        "valid": bool(BRepCheck_Analyzer(shape).IsValid()),
        "volume": float(props.Mass()),
        "bounds": ((x0, y0, z0), (x1, y1, z1)),
        "faces": kinds,
    }
