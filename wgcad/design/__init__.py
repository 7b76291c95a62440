"""Design files: the schema (one module per table family), its declared rules, reading, and the work a design asks for."""

from .budget import *  # noqa: F401,F403
from .budget import __all__ as _budget_all
from .files import *  # noqa: F401,F403
from .files import __all__ as _files_all
from .schema import *  # noqa: F401,F403
from .schema import OPTIONAL_TABLES, TABLES  # noqa: F401
from .schema import __all__ as _schema_all

__all__ = [*_schema_all, *_files_all, *_budget_all]
