"""A part's body (:mod:`wgcad.export.parts.recipe`) as an OpenCASCADE solid wrapped as a build123d ``Part``, its faces
named by the loops and caps they come from.

The walls are OpenCASCADE prisms of the loops' wires (a face-modified ring: the ruled shell between its two
sections), the caps plane faces on the walls' own end wires, and the shell is put together from those faces: they
already share every edge, so no boolean, sewing or healing runs. Each loop is one wire of exact edges: lines and
arcs through the fitted path's vertices, or a whole circle.
build123d and OCP are imported here only (``pip install 'wgcad[cad]'``).
"""

from __future__ import annotations

import numpy as np

from wgcad.errors import GeometryError

__all__ = ["solid", "require"]


def require():
    """The build123d module, or a one-line :class:`~wgcad.errors.DependencyError` saying which extra to install."""
    try:
        import build123d
    except ImportError:
        from wgcad.errors import DependencyError
        from wgcad.extras import message

        raise DependencyError(message("cad")) from None
    return build123d


def _pnt(x, y, z):
    from OCP.gp import gp_Pnt

    return gp_Pnt(float(x), float(y), float(z))


def _wire(loop, z: float, material_left: bool):
    """The loop's wire at height ``z``, run with the material on its left seen from +z."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir
    from OCP.TopoDS import TopoDS_Wire

    from wgcad.export.formats.arcs import arc_points

    flip = loop.ccw != material_left  # the loop's own direction against the one asked for
    wire = TopoDS_Wire()
    bld = BRep_Builder()
    bld.MakeWire(wire)
    if loop.kind == "circle":
        cx, cy = loop.vertices[0]
        axis = gp_Ax2(_pnt(cx, cy, z), gp_Dir(0.0, 0.0, 1.0 if material_left else -1.0))
        bld.Add(wire, BRepBuilderAPI_MakeEdge(gp_Circ(axis, loop.radius)).Edge())
    else:
        v, b = loop.vertices, loop.bulges
        if flip:
            v, b = v[::-1], -np.roll(b[::-1], -1)
        e = np.roll(v, -1, axis=0)
        mid = arc_points(v, e, b, 3)[:, 1, :]
        verts = [BRepBuilderAPI_MakeVertex(_pnt(p[0], p[1], z)).Vertex() for p in v]
        # the plain builder: BRepBuilderAPI_MakeWire searches the wire for shared vertices on every edge added
        # (quadratic in the edges); these edges share their vertices already
        n = len(v)
        for i in range(n):
            if b[i] == 0.0:
                mk = BRepBuilderAPI_MakeEdge(verts[i], verts[(i + 1) % n])
            else:
                arc = GC_MakeArcOfCircle(_pnt(*v[i], z), _pnt(*mid[i], z), _pnt(*e[i], z)).Value()
                mk = BRepBuilderAPI_MakeEdge(arc, verts[i], verts[(i + 1) % n])
            if not mk.IsDone():
                raise GeometryError(f"segment {i} of the {loop.role} outline is degenerate")
            bld.Add(wire, mk.Edge())
    wire.Closed(True)
    return wire


def _faces(shape) -> list:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    out = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        out.append(ex.Current())
        ex.Next()
    return out


def _wall(w) -> tuple[list, object, object]:
    """The wall's side faces (outward) and its bottom and top wires."""
    from OCP.BRepFill import BRepFill_Generator
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Vec
    from OCP.TopoDS import TopoDS

    bottom = _wire(w.loop, w.z0, w.inside)
    if w.top is None:
        mk = BRepPrimAPI_MakePrism(bottom, gp_Vec(0.0, 0.0, float(w.z1 - w.z0)))
        # a prism of a wire whose material lies on its left: OCCT's side faces point into the material
        return [f.Reversed() for f in _faces(mk.Shape())], bottom, TopoDS.Wire(mk.LastShape())
    top = _wire(w.top, w.z1, w.inside)
    if w.loop.kind != w.top.kind or (w.loop.kind == "path" and len(w.loop.vertices) != len(w.top.vertices)):
        raise GeometryError("a ruled wall needs sections of corresponding segments")
    gen = BRepFill_Generator()
    gen.AddWire(bottom)
    gen.AddWire(top)
    gen.Perform()
    # the ruled shell shares the sections' edges; its faces' normals point out of the material already
    return _faces(gen.Shell()), bottom, top


def _cap(c, wires, walls):
    """The cap's plane face on the walls' end wires, its outward normal +z if ``c.up``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.gp import gp_Dir, gp_Pln
    from OCP.TopoDS import TopoDS

    ws = []
    for i, region_inside in c.bounds:
        w = wires[i][0] if c.z == walls[i].z0 else wires[i][1]
        # the walls' wires run with their material on the left; the face's bounds run with the face on the left
        ws.append(w if region_inside == walls[i].inside else TopoDS.Wire(w.Reversed()))
    outer = [k for k, (i, r) in enumerate(c.bounds) if r]
    if len(outer) != 1:
        raise GeometryError(f"the cap at z = {c.z} mm needs one outer boundary")
    mf = BRepBuilderAPI_MakeFace(gp_Pln(_pnt(0.0, 0.0, c.z), gp_Dir(0.0, 0.0, 1.0)), ws[outer[0]], True)
    for k, w in enumerate(ws):
        if k != outer[0]:
            mf.Add(w)
    if not mf.IsDone():
        raise GeometryError(f"the plane face at z = {c.z} mm could not be built")
    face = mf.Face()
    return face if c.up else face.Reversed()


def solid(body, label: str):
    """The body as a build123d ``Part`` labelled ``label``, with ``named_faces``: role -> ``ShapeList`` of its faces
    (the walls' loops' roles, the caps' roles)."""
    bd = require()
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound, TopoDS_Shell, TopoDS_Solid

    bld = BRep_Builder()
    shell = TopoDS_Shell()
    bld.MakeShell(shell)
    named: dict = {}
    wires = []
    for w in body.walls:
        faces, bottom, top = _wall(w)
        wires.append((bottom, top))
        named.setdefault(w.loop.role, []).extend(faces)
    for c in body.caps:
        named.setdefault(c.role, []).append(_cap(c, wires, body.walls))
    for faces in named.values():
        for f in faces:
            bld.Add(shell, f)
    shell.Closed(True)
    solid = TopoDS_Solid()
    bld.MakeSolid(solid)
    bld.Add(solid, shell)
    out = TopoDS_Compound()  # a build123d Part is a compound of solids
    bld.MakeCompound(out)
    bld.Add(out, solid)
    part = bd.Part(out)
    part.label = label
    part.named_faces = {role: bd.ShapeList(bd.Face(f) for f in faces) for role, faces in named.items()}
    return part
