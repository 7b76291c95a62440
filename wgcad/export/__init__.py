"""File exporters (DXF outlines and arcs, STL, 3MF, STEP, SVG; the part set in parts/) and the pictures; the atomic writes they use live in :mod:`wgcad.atomic`.

ezdxf, manifold3d, OpenCASCADE, matplotlib and plotly are imported inside the functions that need them.
"""

from wgcad.atomic import (
    atomic_batch,
    atomic_write,
    atomic_writer,
    commit_all,
    discard_all,
    ensure_writable_dir,
)
from wgcad.export.formats.dxf import DxfLayer, audit_dxf, build_dxf, read_dxf, write_dxf
from wgcad.export.formats.stl import ring_solid, stl_bytes, write_stl

__all__ = [
    "atomic_batch",
    "atomic_write",
    "atomic_writer",
    "commit_all",
    "discard_all",
    "ensure_writable_dir",
    "DxfLayer",
    "build_dxf",
    "write_dxf",
    "read_dxf",
    "audit_dxf",
    "ring_solid",
    "stl_bytes",
    "write_stl",
]
