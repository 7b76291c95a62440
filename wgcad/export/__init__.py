"""File exporters (DXF outlines and arcs, STL, 3MF, STEP, SVG; the part set in parts/), atomic writes, and a registry keyed by file extension.

The DXF and STL modules import ezdxf, trimesh and manifold3d (together ~2 s
on a cold start), so they are loaded on first use of a name that needs them
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
    "EXPORTERS",
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
    if name == "EXPORTERS":
        from wgcad.export.dxf import write_dxf
        from wgcad.export.step import write_step
        from wgcad.export.stl import write_stl
        from wgcad.export.threemf import write_3mf

        #: Exporters keyed by file extension (no dot): ``EXPORTERS[ext](path, obj)``
        #: writes ``obj`` (a sequence of DxfLayer for "dxf", a trimesh.Trimesh
        #: for "stl", ``{name: OCP shape}`` for "step", ``{name: trimesh}``
        #: for "3mf") to ``path`` atomically.
        value = {"dxf": write_dxf, "stl": write_stl, "step": write_step, "3mf": write_3mf}
    elif name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # cache: later lookups bypass __getattr__
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
