"""Reading design files: regular files only, a size limit, TOML nesting that cannot exhaust the stack."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import InputFileError
from ..userfiles import read_user_text
from .schema import Design, parse_design

__all__ = ["MAX_DESIGN_BYTES", "read_design_text", "parse_toml", "load_design"]

#: Largest design file read, bytes. The bundled templates are ~1.5 kB; a
#: design is a few tables of numbers, so 1 MiB is generous and still refuses
#: a device or a huge file before it is read into memory.
MAX_DESIGN_BYTES = 1 << 20


def read_design_text(path) -> str:
    """The text of a design file, read only if it is a regular file of at most :data:`MAX_DESIGN_BYTES`
    (:func:`wgcad.userfiles.read_user_text`).

    Raises
    ------
    InputFileError
        Missing, unreadable, not a regular file, too large, not UTF-8.
    """
    return read_user_text(path, "design file", MAX_DESIGN_BYTES, "TOML")


def load_design(path) -> Design:
    """Read, parse and validate a design file (field rules; the derived geometry is
    checked by :func:`wgcad.drive.build_drive`).

    Raises
    ------
    InputFileError
        Missing, unreadable or not a regular file, too large, invalid or too deeply nested TOML.
    DesignError
        A field rule is broken.
    """
    if isinstance(path, Design):  # already read (a library caller's object): taken as it is
        return path
    p = Path(path)
    return parse_design(parse_toml(read_design_text(p), p, "a design"), source=str(p))


def parse_toml(text: str, path, what: str) -> dict:
    """TOML text of ``path`` as a dict; a one-line :class:`InputFileError` when it is not valid TOML for ``what``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputFileError(f"{path}: not valid TOML ({e})") from None
    except RecursionError:
        # tomllib parses nested arrays and inline tables recursively
        raise InputFileError(f"{path}: not valid TOML for {what} (arrays or tables nested too deeply)") from None
