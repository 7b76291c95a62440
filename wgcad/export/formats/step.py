"""STEP files of build123d shapes (build123d's ``export_step``: OpenCASCADE's XCAF writer, AP214, mm), written
byte-reproducibly, and read back with their checks (validity, volume, bounds, kinds of faces)."""

from __future__ import annotations

import io
import os

from wgcad.atomic import atomic_write
from wgcad.errors import GeometryError

__all__ = ["FIXED_STAMP", "step_bytes", "write_step", "read_step", "solid_props"]

#: the FILE_NAME time stamp, fixed so the same design gives byte-identical files
FIXED_STAMP = "2000-01-01T00:00:00"


def step_bytes(shape) -> bytes:
    """The STEP text of a build123d shape (a labelled ``Part``, or a ``Compound`` of labelled children).

    No 2D parameter curves of the edges on their faces (pcurves): every edge is written as its 3D curve, which is
    the geometry; readers rebuild the pcurves as they load (OpenCASCADE and FreeCAD read the same valid solids, the
    files are less than half the size and written faster). The header's time stamp is fixed; its file name is the
    shape's label.
    """
    from ..parts.kernel import require

    bd = require()
    buf = io.BytesIO()
    if not bd.export_step(shape, buf, write_pcurves=False, timestamp=FIXED_STAMP):
        raise GeometryError(f"STEP writer failed on {shape.label or 'a shape'}")
    return buf.getvalue()


def write_step(path: str | os.PathLike, shape) -> None:
    """Write a build123d shape to a STEP file, atomically."""
    atomic_write(path, step_bytes(shape))


def read_step(path: str | os.PathLike) -> list:
    """Read a STEP file back with OpenCASCADE: its solids (``TopoDS_Solid``), in file order.

    Raises
    ------
    GeometryError
        If the file cannot be read.
    """
    from ..parts.kernel import require

    require()
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Message import Message, Message_Gravity
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    for printer in Message.DefaultMessenger_s().Printers():  # no transfer statistics on stdout
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    r = STEPControl_Reader()
    if r.ReadFile(str(path)) != IFSelect_RetDone:
        raise GeometryError(f"{path}: not a readable STEP file")
    r.TransferRoots()
    out = []
    ex = TopExp_Explorer(r.OneShape(), TopAbs_SOLID)
    while ex.More():
        out.append(TopoDS.Solid(ex.Current()))
        ex.Next()
    return out


def solid_props(shape) -> dict:
    """Validity, volume (mm^3), bounding box ``((x0, y0, z0), (x1, y1, z1))`` and face counts by surface type of a
    solid (a build123d shape or an OCP ``TopoDS_Shape``)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    shape = getattr(shape, "wrapped", shape)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    box = Bnd_Box()
    box.SetGap(0.0)
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    kinds: dict = {}
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        k = str(BRepAdaptor_Surface(TopoDS.Face(ex.Current())).GetType()).split(".")[-1]
        kinds[k] = kinds.get(k, 0) + 1
        ex.Next()
    return {
        "valid": bool(BRepCheck_Analyzer(shape).IsValid()),
        "volume": float(props.Mass()),
        "bounds": ((lo.X(), lo.Y(), lo.Z()), (hi.X(), hi.Y(), hi.Z())),
        "faces": kinds,
    }
