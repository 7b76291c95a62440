"""Elastic contact model of the loaded drive: ring compliance, flexible bearing, tooth contacts, contact solver (docs/models.md 4)."""

from wgcad.elastic.loaded import LoadedLaw
from wgcad.elastic.model import ElasticModel, build_model
from wgcad.elastic.ring import Ring
from wgcad.elastic.solve import ContactSolveError, solve_contact_qp
from wgcad.elastic.state import LoadState, solve_load

__all__ = [
    "Ring",
    "LoadedLaw",
    "ElasticModel",
    "build_model",
    "LoadState",
    "solve_load",
    "ContactSolveError",
    "solve_contact_qp",
]
