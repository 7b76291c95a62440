"""Findings and derived figures as data, shaped into summaries, JSON and baselines."""

from .drive import *  # noqa: F401,F403
from .drive import __all__  # noqa: F401
