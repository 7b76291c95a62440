"""Clearance and interference between the deformed flexspline and the rigid gear (docs/models.md 5, 7)."""

from .distance import signed_clearance
from .engine import AuditResult, AuditSettings, audit, tooth_clearance

__all__ = ["signed_clearance", "AuditSettings", "AuditResult", "audit", "tooth_clearance"]
