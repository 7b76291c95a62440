"""Reading design files: regular files only, a size limit, TOML nesting that cannot exhaust the stack."""

from __future__ import annotations

import os
import stat
import tomllib
from pathlib import Path

from ..errors import InputFileError
from .schema import Design, parse_design

__all__ = ["MAX_DESIGN_BYTES", "read_design_text", "parse_toml", "load_design"]

#: Largest design file read, bytes. The bundled templates are ~1.5 kB; a
#: design is a few tables of numbers, so 1 MiB is generous and still refuses
#: a device or a huge file before it is read into memory.
MAX_DESIGN_BYTES = 1 << 20

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _kind(mode: int) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"  # pragma: no cover


def read_design_text(path) -> str:
    """The text of a design file, read only if it is a regular file of at most :data:`MAX_DESIGN_BYTES`.

    The file is opened without blocking (a FIFO would otherwise wait for a
    writer) and checked on the open descriptor, so what is checked is what
    is read.

    Raises
    ------
    InputFileError
        Missing, unreadable, not a regular file, too large, not UTF-8.
    """
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputFileError(f"{p}: design file not found") from None
    except IsADirectoryError:
        raise InputFileError(f"{p}: the design file is a directory, not a regular file") from None
    except OSError as e:
        raise InputFileError(f"{p}: cannot read design file ({e.strerror})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputFileError(f"{p}: the design file is {_kind(st.st_mode)}, not a regular file")
        if st.st_size > MAX_DESIGN_BYTES:
            raise InputFileError(
                f"{p}: design file of {st.st_size} bytes is larger than the limit of {MAX_DESIGN_BYTES} bytes"
            )
        chunks, size = [], 0
        while True:  # the size may change while reading: read at most one byte past the limit
            b = os.read(fd, MAX_DESIGN_BYTES + 1 - size)
            if not b:
                break
            chunks.append(b)
            size += len(b)
            if size > MAX_DESIGN_BYTES:
                raise InputFileError(f"{p}: design file is larger than the limit of {MAX_DESIGN_BYTES} bytes")
    except OSError as e:
        if isinstance(e, InputFileError):
            raise
        raise InputFileError(f"{p}: cannot read design file ({e.strerror})") from None
    finally:
        os.close(fd)
    try:
        return b"".join(chunks).decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputFileError(f"{p}: not valid TOML (not UTF-8 text: {e.reason} at byte {e.start})") from None


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
