"""The optional extras: which package each brings, what needs it, and the one-line error when it is missing.

A command checks its extras before any work (:func:`require`: a look-up of the module, not an import, so the check
costs nothing and the heavy import stays where the package is used); the edge functions check again, so a library
caller gets the same line instead of a bare ``ModuleNotFoundError``. The extras themselves are declared in
``pyproject.toml`` (``[project.optional-dependencies]``); tests/test_packaging.py checks the two agree.
"""

from __future__ import annotations

import importlib.util

from .errors import DependencyError

__all__ = ["EXTRAS", "require", "missing", "message"]

#: extra -> (the module whose presence stands for it, the distribution to name, what needs it)
EXTRAS = {
    "sweep": ("distributed", "dask.distributed", "sweeps and parallel design searches"),
    "design": ("optuna", "optuna", "the design search"),
    "html": ("plotly", "plotly", "the HTML pages"),
    "plots": ("matplotlib", "matplotlib", "the PNG pictures"),
    "cad": ("build123d", "build123d", "the CAD solids (STEP, wgcad.cad)"),
}


def _present(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent package missing, or a module set to None in sys.modules
        return False


def missing(*extras: str) -> list[str]:
    """The extras among ``extras`` whose package is not installed, in the order given."""
    for e in extras:
        if e not in EXTRAS:
            raise KeyError(f"unknown extra {e!r}; known: {', '.join(EXTRAS)}")
    return [e for e in extras if not _present(EXTRAS[e][0])]


def message(extra: str, what: str = "") -> str:
    """The line a user without ``extra`` reads; ``what`` (a command or flag, ``"--html"``) goes in front."""
    _, dist, needs = EXTRAS[extra]
    return f"{what + ': ' if what else ''}{needs} need {dist}: pip install 'wgcad[{extra}]'"


def require(*extras: str, what: str = "") -> None:
    """Raise a one-line :class:`~wgcad.errors.DependencyError` (exit 5) naming the first of ``extras`` missing."""
    gone = missing(*extras)
    if gone:
        raise DependencyError(message(gone[0], what))
