"""Where outputs may go: a target that is missing or a regular file, a folder that takes new files (refused with a one-line reason otherwise)."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from wgcad.errors import OutputError

from .temps import new_temp, remove_quietly

__all__ = ["check_target", "check_writable_dir", "ensure_writable_dir"]

# Pseudo file systems that hold kernel objects, not files: an output folder
# there is refused with the file system named (creating a file in /proc says
# "No such file or directory", which misleads).
_PSEUDO_FS = {
    "proc": "the kernel's process table",
    "sysfs": "the kernel's device tree",
    "devtmpfs": "device files",
    "devpts": "terminal devices",
    "cgroup": "control groups",
    "cgroup2": "control groups",
    "debugfs": "kernel debugging data",
    "tracefs": "kernel tracing data",
    "securityfs": "kernel security data",
    "configfs": "kernel configuration objects",
    "bpf": "BPF objects",
    "mqueue": "message queues",
    "pstore": "kernel crash records",
    "efivarfs": "firmware variables",
    "fusectl": "FUSE control files",
    "binfmt_misc": "binary-format rules",
}


def os_reason(exc: OSError) -> str:
    """Short reason of an OS error, without the path (the caller names it)."""
    return exc.strerror or type(exc).__name__


def _kind(mode: int) -> str:
    """Name of a file type, for messages."""
    for test, name in (
        (stat.S_ISREG, "a regular file"),
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a named pipe (FIFO)"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"  # pragma: no cover (doors, whiteouts)


def not_a_folder(path: Path) -> str:
    """Why ``path`` cannot be reached: the first component of it that exists but is not a folder."""
    p = Path(os.path.abspath(path))
    for part in [*reversed(p.parents), p]:
        try:
            mode = os.stat(part).st_mode
        except OSError:
            break
        if not stat.S_ISDIR(mode):
            return f"{part} is {_kind(mode)}, not a folder"
    return "a part of the path is not a folder"


def check_target(path: str | os.PathLike, hint: str = "") -> Path:
    """Check that ``path`` may be replaced by a new regular file: it is missing or a regular file.

    A device (``/dev/null``, ``/dev/stdout``), FIFO, socket, folder or symbolic
    link is refused, whoever runs wgcad (root included): renaming a file onto
    it would silently replace the device or link.

    Parameters
    ----------
    path : str or path-like
        The final file name.
    hint : str, optional
        Appended to the message (e.g. "use - for standard output").

    Returns
    -------
    Path

    Raises
    ------
    OutputError
        ``"<path>: is a character device; wgcad writes only new or regular files"``.
    """
    final = Path(path)
    try:
        mode = os.lstat(final).st_mode
    except FileNotFoundError:
        return final
    except NotADirectoryError as exc:
        raise OutputError(f"{final.parent}: output folder is not writable ({not_a_folder(final.parent)})") from exc
    except OSError as exc:
        raise OutputError(f"{final}: cannot write file ({os_reason(exc)})") from exc
    if stat.S_ISREG(mode):
        return final
    raise OutputError(f"{final}: is {_kind(mode)}; wgcad writes only new or regular files{hint}")


def _mount_type(folder: Path) -> str | None:
    """File-system type of the mount holding ``folder`` (Linux ``/proc/self/mounts``), or None."""
    try:
        real = os.path.realpath(folder)
        with open("/proc/self/mounts", encoding="utf-8", errors="replace") as fp:
            rows = [line.split() for line in fp]
    except OSError:
        return None
    best, best_len = None, -1
    for row in rows:
        if len(row) < 3:
            continue
        mnt = row[1].replace("\\040", " ")
        inside = real == mnt or real.startswith(mnt.rstrip("/") + "/")
        if inside and len(mnt) > best_len:
            best, best_len = row[2], len(mnt)
    return best


def check_writable_dir(path: str | os.PathLike) -> Path:
    """Check that files can be written in folder ``path`` without creating anything that stays.

    The folder may be missing: then its nearest existing ancestor must be a
    writable folder (the missing part is created only when the files are
    written, so a refused run leaves no empty folder behind). Writability is
    probed by creating and removing a temporary file, because ``os.access``
    says yes to root even on a read-only mount.

    Parameters
    ----------
    path : str or path-like
        The output folder.

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    OutputError
        ``"<dir>: output folder is not writable (<reason>)"``.
    """
    folder = Path(path)
    probe_dir = Path(os.path.abspath(folder))
    while True:
        try:
            st = os.stat(probe_dir)
            break
        except FileNotFoundError:
            if probe_dir.parent == probe_dir:  # pragma: no cover (the root always exists)
                raise OutputError(f"{folder}: output folder is not writable (no existing parent folder)") from None
            probe_dir = probe_dir.parent
        except NotADirectoryError:
            raise OutputError(f"{folder}: output folder is not writable ({not_a_folder(folder)})") from None
        except OSError as exc:
            raise OutputError(f"{folder}: output folder is not writable ({os_reason(exc)})") from exc
    if not stat.S_ISDIR(st.st_mode):
        which = "it" if probe_dir == Path(os.path.abspath(folder)) else str(probe_dir)
        raise OutputError(f"{folder}: output folder is not writable ({which} is {_kind(st.st_mode)}, not a folder)")
    fs = _mount_type(probe_dir)
    if fs in _PSEUDO_FS:
        raise OutputError(
            f"{folder}: output folder is not writable (it is on a {fs} file system, which holds {_PSEUDO_FS[fs]}, not files)"
        )
    try:
        probe = new_temp(probe_dir / ".wgcad-write-probe")
    except OSError as exc:
        if exc.errno == errno.ENOENT:  # the folder exists, yet "no such file": a special file system
            reason = f"the file system refuses new files there ({os_reason(exc)})"
        else:
            reason = os_reason(exc)
        raise OutputError(f"{folder}: output folder is not writable ({reason})") from exc
    remove_quietly(probe)
    return folder


def ensure_writable_dir(path: str | os.PathLike) -> Path:
    """Create an output folder (with parents) after :func:`check_writable_dir` passed.

    Prefer :func:`check_writable_dir` before a computation and let the write
    create the folder: then a run refused later leaves no empty folder.

    Raises
    ------
    OutputError
        As :func:`check_writable_dir`, or when the folder cannot be created.
    """
    folder = check_writable_dir(path)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{folder}: output folder is not writable ({os_reason(exc)})") from exc
    return folder
