"""File exporters (DXF outlines and arcs, STL, 3MF, STEP, SVG; the part set in parts/) and the pictures; the atomic writes they use live in :mod:`wgcad.atomic`.

Reading DXF imports ezdxf, a ring the zipper cannot triangulate manifold3d
(together ~0.15 s warm, more on a cold start), so the modules are loaded on first use of a name that needs them
(PEP 562 module ``__getattr__``): ``import wgcad.atomic`` or
``wgcad --help`` stays light.
"""

import importlib

from wgcad.atomic import (
    atomic_batch,
    atomic_write,
    atomic_writer,
    commit_all,
    discard_all,
    ensure_writable_dir,
)

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

_LAZY = {
    "DxfLayer": "wgcad.export.dxf",
    "build_dxf": "wgcad.export.dxf",
    "write_dxf": "wgcad.export.dxf",
    "read_dxf": "wgcad.export.dxf",
    "audit_dxf": "wgcad.export.dxf",
    "ring_solid": "wgcad.export.stl",
    "stl_bytes": "wgcad.export.stl",
    "write_stl": "wgcad.export.stl",
}


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # cache: later lookups bypass __getattr__
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
