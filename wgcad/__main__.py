"""``python -m wgcad``."""

from .cli import run

run()
