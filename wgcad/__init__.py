"""wgcad: geometry, deformation and clearance of harmonic (strain-wave) drives.

Each command of the CLI is one call that takes a design (a file's path, a ``Design`` or a built ``Drive``) and
returns a record whose ``doc`` is the command's ``--json`` document (:mod:`wgcad.api`); the pipeline's lower entry
points beside them. All are loaded on first use (PEP 562: ``import wgcad`` stays light)::

    import wgcad
    design = wgcad.load_design("templates/d1_involute.toml")
    run = wgcad.audit(design)                       # wgcad audit: run.result.findings, run.doc, run.failed
    ke = wgcad.kinematic_error("templates/d2_imperfect.toml")        # wgcad ke: ke.res.ke_pp (rad), ke.doc
    sheet = wgcad.rating(design)                    # wgcad rating: sheet.datasheet.rated_torque_nm
    loaded = wgcad.load_audit(design, [100, 200])   # wgcad audit --torque-nm: loaded.doc["levels"]
    part_set = wgcad.parts("templates/d1_involute.toml")   # wgcad parts: part_set.parts, each .solid()

``wgcad.audit`` and ``wgcad.rating`` are also the modules of those names (``from wgcad.audit import RunSettings``):
called, they run :func:`wgcad.api.audit` and :func:`wgcad.api.rating`.
"""

import importlib
import sys
import types

__version__ = "0.1.0"

#: name -> module that defines it (docs/architecture.md: each from its own floor)
_ENTRY = {
    "load_design": "wgcad.design",
    "build_drive": "wgcad.drive",
    "RunSettings": "wgcad.audit",
    "run_audit": "wgcad.audit",
    "audit_document": "wgcad.services.audit_report",
    "audit_json": "wgcad.report.audit",
    "audit": "wgcad.audit",
    "load_audit": "wgcad.api",
    "contact_table": "wgcad.accuracy.ke",
    "kinematic_error": "wgcad.api",
    "rating": "wgcad.rating",
    "parts": "wgcad.api",
    "build_model": "wgcad.elastic",
    "solve_load": "wgcad.elastic",
    "build_parts": "wgcad.export.parts",
    "write_drive_files": "wgcad.export.files.drive",
    "run_sector": "wgcad.sector.run",
    "load_spec": "wgcad.sweep.spec",
    "run_sweep": "wgcad.sweep.runner",
}
__all__ = ["__version__", *_ENTRY]


class _EntryModule(types.ModuleType):
    """A module that is an entry point too: called, it runs :mod:`wgcad.api`'s function of its own name, so
    ``wgcad.audit(design)`` works beside ``from wgcad.audit import RunSettings`` (a package's submodule is set as
    the package's attribute on import, so the name cannot be a plain function)."""

    def __call__(self, *args, **kwargs):
        return getattr(importlib.import_module("wgcad.api"), self.__name__.rsplit(".", 1)[1])(*args, **kwargs)


def entry_module(name: str) -> None:
    """Make the module ``name`` (being imported) callable as its entry point (:class:`_EntryModule`)."""
    sys.modules[name].__class__ = _EntryModule


def __getattr__(name):
    module = _ENTRY.get(name)
    if module is None:
        raise AttributeError(f"module 'wgcad' has no attribute {name!r}")
    imported = importlib.import_module(module)
    value = imported if module == f"wgcad.{name}" else getattr(imported, name)
    globals()[name] = value  # once looked up, a plain attribute
    return value


def __dir__():
    return sorted(__all__)
