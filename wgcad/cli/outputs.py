"""Output paths of the CLI: checks before any work, ``-`` for standard output (the manifest of ``generate`` lives in :mod:`wgcad.export.files.manifest`)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from ..atomic import check_target, check_writable_dir
from ..errors import OutputError

__all__ = ["STDOUT", "check_output_file", "check_output_dir", "write_stdout"]

#: the output path that means standard output
STDOUT = "-"


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def check_output_file(path, *, flag: str, inputs=(), stdout_ok: bool = False) -> Path:
    """Check an output file given on the command line before anything is computed or written.

    It must be missing or a regular file (not a device, FIFO, socket, folder
    or symbolic link: those are never replaced), its folder must be writable
    (or creatable), and it must not be one of the input files.

    Parameters
    ----------
    path : str or path-like
    flag : str
        The flag that named it (for the message).
    inputs : iterable of path
        Files the run reads (the design, a baseline), which it must not replace.
    stdout_ok : bool
        Whether ``-`` (standard output) is allowed for this flag; the hint
        in the message mentions it.

    Raises
    ------
    OutputError
    """
    p = Path(path)
    hint = f" (give {flag} - to write to standard output)" if stdout_ok else ""
    try:
        check_target(p, hint=hint)
    except OutputError as exc:
        raise OutputError(f"{flag}: {exc}") from None
    for inp in inputs:
        if inp is not None and p.exists() and _same_file(p, Path(inp)):
            raise OutputError(f"{flag}: {p} is an input of this run; it would be overwritten")
    check_writable_dir(p.parent)
    return p


def check_output_dir(path) -> Path:
    """Check an output folder (``--out``) before anything is computed; nothing is created."""
    return check_writable_dir(path)


def write_stdout(text: str) -> None:
    """Write to standard output; a full disk or closed pipe becomes an :class:`OutputError`."""
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:
        raise  # the reader stopped (``| head``): main() exits quietly
    except OSError as exc:
        raise OutputError(f"standard output: cannot write ({exc.strerror or type(exc).__name__})") from exc
