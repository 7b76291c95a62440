"""Reading a user's file (design, sweep spec, baseline, sweep metadata): regular files only, a size limit, UTF-8 text.

The file is opened without blocking (a FIFO would otherwise wait for a
writer) and checked on the open descriptor, so what is checked is what is
read; a device or a huge file is refused before it is read into memory.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .errors import InputFileError

__all__ = ["read_user_text"]

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


def read_user_text(path, what: str, max_bytes: int, kind: str = "text") -> str:
    """The text of ``path`` (a ``what``, e.g. "design file"), read only if it is a regular file of at most
    ``max_bytes``; a UTF-8 byte-order mark is dropped.

    Raises
    ------
    InputFileError
        Missing, unreadable, not a regular file, too large, not UTF-8 (``kind`` names what it should be).
    """
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputFileError(f"{p}: {what} not found") from None
    except IsADirectoryError:
        raise InputFileError(f"{p}: the {what} is a directory, not a regular file") from None
    except OSError as e:
        raise InputFileError(f"{p}: cannot read {what} ({e.strerror})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputFileError(f"{p}: the {what} is {_kind(st.st_mode)}, not a regular file")
        if st.st_size > max_bytes:
            raise InputFileError(f"{p}: {what} of {st.st_size} bytes is larger than the limit of {max_bytes} bytes")
        chunks, size = [], 0
        while True:  # the size may change while reading: read at most one byte past the limit
            b = os.read(fd, max_bytes + 1 - size)
            if not b:
                break
            chunks.append(b)
            size += len(b)
            if size > max_bytes:
                raise InputFileError(f"{p}: {what} is larger than the limit of {max_bytes} bytes")
    except OSError as e:
        if isinstance(e, InputFileError):
            raise
        raise InputFileError(f"{p}: cannot read {what} ({e.strerror})") from None
    finally:
        os.close(fd)
    try:
        return b"".join(chunks).decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InputFileError(f"{p}: not valid {kind} (not UTF-8 text: {e.reason} at byte {e.start})") from None
