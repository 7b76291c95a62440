"""Temporary files of the atomic writes: their names, their creation beside the target, and the removal of those a killed run left behind."""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import stat
import time
from pathlib import Path

__all__ = ["TEMP_SUFFIX", "remove_stale_temps", "shown_name"]

#: Temporary files are hidden (leading dot) and named
#: ``.<final name>.<pid>-<12 hex digits>.tmp``: a run killed with SIGKILL
#: leaves recognisable files behind, and the pid tells a later run whether
#: their writer is gone (then they are removed, see :func:`remove_stale_temps`).
TEMP_SUFFIX = ".tmp"

_TEMP_RE = re.compile(r"^\..+\.(\d+)-[0-9a-f]{12}\.tmp$")
# wgcad 0.1.0 named them without the pid; such files are removed once they
# have not been touched for this long (no writer keeps a file open that long
# without writing to it... except a very large export, hence a generous hour)
_LEGACY_TEMP_RE = re.compile(r"^\..+\.[0-9a-f]{12}\.tmp$")
_LEGACY_TEMP_AGE_S = 3600.0


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0  # another user's live process (or a pid we cannot judge): keep its files
    return True


def remove_stale_temps(folder: str | os.PathLike) -> list[str]:
    """Remove wgcad's temporary files in ``folder`` whose writer is gone (a run killed before it could clean up).

    Only regular files named like wgcad's own temporaries are touched:
    ``.<name>.<pid>-<12 hex>.tmp`` whose process no longer exists, and the
    pid-less names of wgcad 0.1.0 untouched for an hour. A temporary file of
    a run still writing (its pid alive) is left alone.

    Parameters
    ----------
    folder : str or path-like

    Returns
    -------
    list of str
        The names removed.
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    now = time.time()
    for entry in entries:
        name = entry.name
        if not name.endswith(TEMP_SUFFIX) or not name.startswith("."):
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if not stat.S_ISREG(st.st_mode):
            continue
        m = _TEMP_RE.match(name)
        if m:
            stale = not _pid_alive(int(m.group(1)))
        else:
            stale = bool(_LEGACY_TEMP_RE.match(name)) and now - st.st_mtime > _LEGACY_TEMP_AGE_S
        if stale:
            with contextlib.suppress(OSError):
                os.remove(entry.path)
                removed.append(name)
    return removed


def shown_name(path: str | os.PathLike) -> Path:
    """The file a user asked for behind ``path``: ``path`` itself, or, for one of wgcad's temporary files (an exporter
    writing atomically onto a batch's temporary name), the final file it stands for. Error messages name that file:
    ``.x.stl.123-0123456789ab.tmp: cannot write file`` tells a user nothing about ``x.stl``."""
    p = Path(path)
    name = p.name
    while True:
        m = _TEMP_RE.match(name) or _LEGACY_TEMP_RE.match(name)
        if not m:
            return p.with_name(name)
        name = name[1 : name.rindex(".", 0, len(name) - len(TEMP_SUFFIX))]


def new_temp(final: Path) -> str:
    """Create an empty temporary file beside ``final`` and return its path.

    ``os.open(..., 0o666)`` rather than ``tempfile.mkstemp`` so the file gets
    the usual permissions after the umask (``mkstemp`` makes it 0600, and that
    mode would survive the rename).
    """
    for _ in range(100):
        temp = final.parent / f".{final.name}.{os.getpid()}-{secrets.token_hex(6)}{TEMP_SUFFIX}"
        try:
            fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return str(temp)
    raise FileExistsError(f"{final.parent}: no free temporary file name")  # pragma: no cover


def remove_quietly(path: str | os.PathLike) -> None:
    """Remove a temporary file if it can be: one the file system will not let go (turned read-only under the run)
    stays for the next run's :func:`remove_stale_temps`, and the error that stopped this run is the one reported."""
    with contextlib.suppress(OSError):
        os.remove(path)
