"""The library's audit module: ``from wgcad.audit import RunSettings, run_audit``; called,
``wgcad.audit(design, settings)`` is :func:`wgcad.api.audit`. The run itself is :mod:`wgcad.services.audit`."""

from __future__ import annotations

from . import entry_module
from .services.audit import BOUNDS, FLAGS, RunSettings, audit_settings, run_audit

__all__ = ["BOUNDS", "FLAGS", "RunSettings", "audit_settings", "run_audit"]

entry_module(__name__)  # wgcad.audit(design, settings): wgcad.api.audit
