"""wgcad: geometry, deformation and clearance of harmonic (strain-wave) drives.

The pipeline's entry points, loaded on first use (PEP 562: ``import wgcad``
stays light, and no subpackage is imported until its name is asked for)::

    import wgcad
    design = wgcad.load_design("templates/d1_involute.toml")
    drive = wgcad.build_drive(design)
    run = wgcad.audit_document("templates/d1_involute.toml", wgcad.RunSettings())   # what `wgcad audit --json` writes
    run.doc["worst"], run.failed
"""

import importlib

__version__ = "0.1.0"

#: name -> module that defines it (docs/architecture.md: each from its own floor)
_ENTRY = {
    "load_design": "wgcad.design",
    "build_drive": "wgcad.drive",
    "RunSettings": "wgcad.audit",
    "run_audit": "wgcad.audit",
    "audit_document": "wgcad.report.audit_run",
    "audit_json": "wgcad.report.audit",
    "contact_table": "wgcad.accuracy.ke",
    "kinematic_error": "wgcad.accuracy.ke",
    "build_model": "wgcad.elastic",
    "solve_load": "wgcad.elastic",
    "build_parts": "wgcad.export.parts",
    "write_drive_files": "wgcad.export.drive_files",
    "run_sector": "wgcad.sector.run",
    "load_spec": "wgcad.sweep.spec",
    "run_sweep": "wgcad.sweep.runner",
}
__all__ = ["__version__", *_ENTRY]


def __getattr__(name):
    module = _ENTRY.get(name)
    if module is None:
        raise AttributeError(f"module 'wgcad' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # once looked up, a plain attribute
    return value


def __dir__():
    return sorted(__all__)
