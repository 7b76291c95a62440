"""Design files: the schema (one module per table family) and its single validation entry point."""

from .schema import *  # noqa: F401,F403
from .schema import _TABLES, __all__  # noqa: F401
