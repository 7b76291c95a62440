"""The error hierarchy of wgcad: one base class, subclasses that also inherit the builtin they resemble."""

import difflib

__all__ = [
    "WgcadError",
    "DesignError",
    "InputFileError",
    "OutputError",
    "GeometryError",
    "ModelError",
    "EXIT_MODEL",
    "DependencyError",
    "EXIT_DEPENDENCY",
    "FolderBusyError",
    "EXIT_BUSY",
    "close_matches",
]


class WgcadError(Exception):
    """Base class of every error wgcad raises on purpose."""

    #: exit code the CLI uses for this kind of error
    exit_code = 2


class DesignError(WgcadError, ValueError):
    """A design parameter (or a geometry derived from it) breaks a rule.

    The message names the field (``table.key``) and the rule.
    """

    def __init__(self, field: str, rule: str):
        self.field = field
        self.rule = rule
        super().__init__(f"{field}: {rule}")


class InputFileError(WgcadError, OSError):
    """An input file is missing, unreadable or not valid TOML."""


class OutputError(WgcadError, OSError):
    """An output folder or file cannot be written."""


class GeometryError(WgcadError, ArithmeticError):
    """A geometric construction failed although the design passed validation."""


#: exit code of :class:`ModelError`: the input is valid, the model could not answer for it
EXIT_MODEL = 4


class ModelError(WgcadError, ArithmeticError):
    """A model did not converge, or the drive lies outside what it represents (the input itself is valid).

    The message says what failed and what to change (a tolerance, a load, the design's clearances).
    """

    exit_code = EXIT_MODEL


#: exit code of :class:`DependencyError`: an optional extra the command needs is not installed
EXIT_DEPENDENCY = 5


class DependencyError(WgcadError, ImportError):
    """A command needs a package of an optional extra that is not installed; the message names the extra."""

    exit_code = EXIT_DEPENDENCY


#: exit code of :class:`FolderBusyError`: the output folder is another live run's
EXIT_BUSY = 6


class FolderBusyError(WgcadError, OSError):
    """A results folder (a sweep's, a design study's) is held by another run still alive: two runs writing one
    journal or one set of chunks would leave it mixed. Nothing is written; the message names the holder's pid."""

    exit_code = EXIT_BUSY


def close_matches(word: str, known) -> list[str]:
    """The entry of ``known`` closest to a mistyped ``word`` (difflib's ratio >= 0.6) as a list, empty if none: a
    message's "did you mean"."""
    return difflib.get_close_matches(word, known, n=1)
