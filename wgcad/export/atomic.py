"""Atomic file writes: write to a temporary file in the target folder, then rename it into place."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import signal
import stat
import time
from collections.abc import Iterable, Iterator
from pathlib import Path

from wgcad.errors import OutputError

__all__ = [
    "TEMP_SUFFIX",
    "check_target",
    "check_writable_dir",
    "ensure_writable_dir",
    "remove_stale_temps",
    "atomic_writer",
    "atomic_write",
    "commit_all",
    "discard_all",
    "Batch",
    "atomic_batch",
]

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

# Signals deferred while a batch renames its files into place, so that an
# interrupt never leaves half of a batch committed.
_DEFERRED = tuple(s for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP")) if s is not None)


def _reason(exc: OSError) -> str:
    """Short reason of an OS error, without the path (the caller names it)."""
    return exc.strerror or type(exc).__name__


def _kind(mode: int) -> str:
    """Name of a non-regular file type, for messages."""
    for test, name in (
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


def _not_a_folder(path: Path) -> str:
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
        raise OutputError(f"{final.parent}: output folder is not writable ({_not_a_folder(final.parent)})") from exc
    except OSError as exc:
        raise OutputError(f"{final}: cannot write file ({_reason(exc)})") from exc
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
            raise OutputError(f"{folder}: output folder is not writable ({_not_a_folder(folder)})") from None
        except OSError as exc:
            raise OutputError(f"{folder}: output folder is not writable ({_reason(exc)})") from exc
    if not stat.S_ISDIR(st.st_mode):
        which = "it" if probe_dir == Path(os.path.abspath(folder)) else str(probe_dir)
        raise OutputError(f"{folder}: output folder is not writable ({which} is {_kind(st.st_mode)}, not a folder)")
    fs = _mount_type(probe_dir)
    if fs in _PSEUDO_FS:
        raise OutputError(f"{folder}: output folder is not writable (it is on a {fs} file system, which holds {_PSEUDO_FS[fs]}, not files)")
    try:
        probe = _new_temp(probe_dir / ".wgcad-write-probe")
    except OSError as exc:
        if exc.errno == errno.ENOENT:  # the folder exists, yet "no such file": a special file system
            reason = f"the file system refuses new files there ({_reason(exc)})"
        else:
            reason = _reason(exc)
        raise OutputError(f"{folder}: output folder is not writable ({reason})") from exc
    _remove_quietly(probe)
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
        raise OutputError(f"{folder}: output folder is not writable ({_reason(exc)})") from exc
    return folder


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


def _new_temp(final: Path) -> str:
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


def _make_parents(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; return the folders created, outermost first."""
    missing = []
    p = folder
    while not os.path.lexists(p):
        missing.append(p)
        if p.parent == p:
            break
        p = p.parent
    folder.mkdir(parents=True, exist_ok=True)
    return list(reversed(missing))


def _prepare_temp(final: Path, created: list[Path] | None = None) -> str:
    """Create the folder of ``final`` and an empty temporary file beside it; OutputError if it cannot."""
    try:
        made = _make_parents(final.parent)
        if created is not None:
            created.extend(made)
        return _new_temp(final)
    except OSError as exc:
        if isinstance(exc, NotADirectoryError):
            reason = _not_a_folder(final.parent)
        elif exc.errno == errno.ENOENT and final.parent.is_dir():
            reason = f"the file system refuses new files there ({_reason(exc)})"
        else:
            reason = _reason(exc)
        raise OutputError(f"{final.parent}: output folder is not writable ({reason})") from exc


def _remove_quietly(path: str | os.PathLike) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.remove(path)


def _remove_empty_dirs(created: list[Path]) -> None:
    """Remove the folders a failed write created (innermost first), if they are still empty."""
    for folder in reversed(created):
        with contextlib.suppress(OSError):
            os.rmdir(folder)


def _fsync(path: str) -> None:
    """Flush the file to disk so the rename cannot expose an empty file after a crash."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold SIGINT/SIGTERM/SIGHUP back (they are delivered at the end) so a group of renames is not cut in half."""
    if not _DEFERRED or not hasattr(signal, "pthread_sigmask"):  # pragma: no cover (not POSIX)
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _DEFERRED)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def atomic_writer(path: str | os.PathLike) -> Iterator[str]:
    """Context manager yielding a temporary path that is renamed onto ``path`` on success.

    The temporary file is created (empty) in the folder of ``path``, so the
    final ``os.replace`` is an atomic rename on the same file system: readers
    see either the old file or the complete new one, never a partial write.
    On any exception (including ``KeyboardInterrupt``) the temporary file is
    removed, ``path`` is left untouched, and folders created for it are
    removed again. ``path`` must be missing or a regular file
    (:func:`check_target`).

    Parameters
    ----------
    path : str or path-like
        Final file name.

    Yields
    ------
    str
        Temporary file name to write to (it already exists, empty; writers
        may overwrite or replace it).

    Raises
    ------
    OutputError
        When ``path`` is not a regular file, the temporary file cannot be
        created, the body raises an ``OSError``, or the rename fails. The
        message names ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_writer(d / "a.txt") as tmp:
    ...     _ = pathlib.Path(tmp).write_text("done")
    >>> (d / "a.txt").read_text()
    'done'
    """
    final = check_target(path)
    created: list[Path] = []
    temp = _prepare_temp(final, created)
    try:
        yield temp
        _fsync(temp)
        check_target(final)  # again: it may have become a link or FIFO while we computed
        os.replace(temp, final)
    except OutputError:
        _remove_quietly(temp)
        _remove_empty_dirs(created)
        raise
    except OSError as exc:
        _remove_quietly(temp)
        _remove_empty_dirs(created)
        raise OutputError(f"{final}: cannot write file ({_reason(exc)})") from exc
    except BaseException:
        _remove_quietly(temp)
        _remove_empty_dirs(created)
        raise


def atomic_write(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_writer`).

    Parameters
    ----------
    path : str or path-like
        Final file name.
    data : bytes
        Complete file content.

    Raises
    ------
    OutputError
        When the file cannot be written; ``path`` is then unchanged.
    """
    with atomic_writer(path) as temp:
        with open(temp, "wb") as fp:
            fp.write(data)


def discard_all(temps: Iterable[str | os.PathLike]) -> None:
    """Remove temporary files, ignoring those already gone.

    Parameters
    ----------
    temps : iterable of str or path-like
        Temporary files prepared for :func:`commit_all`.
    """
    for temp in temps:
        _remove_quietly(temp)


def commit_all(pairs: Iterable[tuple[str | os.PathLike, str | os.PathLike]],
               remove: Iterable[str | os.PathLike] = ()) -> None:
    """Rename several prepared temporary files onto their final names (and remove obsolete files).

    Every temporary file is checked (exists, regular file), every final name
    re-checked (:func:`check_target`) and every file flushed to disk before
    the first rename, so the renames only fail on a fault of the file system
    itself. SIGINT, SIGTERM and SIGHUP are held back during the removals and
    renames (and delivered right after), so an interrupt never commits half
    of a batch. Renames are atomic one by one, not as a group: if rename
    number k fails, files 1..k-1 are already in place, the remaining
    temporary files are removed, and the error says how many were committed.

    Parameters
    ----------
    pairs : iterable of (final_path, temp_path)
        Each temporary file must be in the folder of its final path (as
        :meth:`Batch.temp_path` arranges).
    remove : iterable of path
        Files to delete just before the renames (e.g. a previous run's files
        that the new one does not write).

    Raises
    ------
    OutputError
        When a temporary file is missing, a final name is not a regular file,
        or a rename fails. All temporary files not yet renamed are removed
        first.
    """
    pairs = [(Path(final), str(temp)) for final, temp in pairs]
    final = None
    try:
        for final, temp in pairs:
            if not os.path.isfile(temp):
                raise OutputError(f"{final}: cannot write file (prepared temporary file {temp} is missing)")
            check_target(final)
            _fsync(temp)
    except OSError as exc:
        discard_all(temp for _, temp in pairs)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"{final}: cannot write file ({_reason(exc)})") from exc
    with _signals_deferred():
        for old in remove:
            with contextlib.suppress(FileNotFoundError):
                os.remove(old)
        for k, (final, temp) in enumerate(pairs):
            try:
                os.replace(temp, final)
            except OSError as exc:
                discard_all(t for _, t in pairs[k:])
                raise OutputError(
                    f"{final}: cannot write file ({_reason(exc)}); "
                    f"{k} of {len(pairs)} files were already written"
                ) from exc


class Batch:
    """Temporary files of a multi-file write, committed together by :func:`atomic_batch`."""

    def __init__(self) -> None:
        self.pairs: list[tuple[Path, str]] = []
        self.removals: list[Path] = []
        self.created: list[Path] = []
        self._swept: set[str] = set()

    def temp_path(self, path: str | os.PathLike) -> str:
        """Create and register an empty temporary file for the final file ``path``.

        The first time a folder is used, wgcad's temporary files left there
        by killed runs are removed (:func:`remove_stale_temps`).

        Parameters
        ----------
        path : str or path-like
            Final file name; its folder is created if missing (and removed
            again if the batch fails).

        Returns
        -------
        str
            Temporary file in the same folder. Write the complete content
            there, e.g. with an exporter: ``write_dxf(batch.temp_path(p), layers)``
            (the exporter's own atomic rename onto the temporary name is harmless).

        Raises
        ------
        OutputError
            When ``path`` is not a regular file (:func:`check_target`), the
            folder is not writable, or ``path`` was registered before.
        """
        final = check_target(path)
        if any(os.path.abspath(final) == os.path.abspath(f) for f, _ in self.pairs):
            raise OutputError(f"{final}: cannot write file (listed twice in one batch)")
        folder = os.path.abspath(final.parent)
        if folder not in self._swept:
            self._swept.add(folder)
            remove_stale_temps(folder)
        temp = _prepare_temp(final, self.created)
        self.pairs.append((final, temp))
        return temp

    def remove_on_commit(self, path: str | os.PathLike) -> None:
        """Delete ``path`` together with the commit (nothing happens if the batch fails)."""
        self.removals.append(Path(path))

    def discard(self) -> None:
        """Remove every temporary file and the folders this batch created."""
        discard_all(temp for _, temp in self.pairs)
        _remove_empty_dirs(self.created)


@contextlib.contextmanager
def atomic_batch() -> Iterator[Batch]:
    """Write several files so that a failure while preparing any of them writes none.

    Yields a :class:`Batch`; ask it for one temporary path per output file
    and write to those. On normal exit all are renamed into place by
    :func:`commit_all`; on any exception all temporary files are removed, no
    final file is touched, and folders the batch created are removed.

    Yields
    ------
    Batch

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_batch() as batch:
    ...     for name in ("a.txt", "b.txt"):
    ...         _ = pathlib.Path(batch.temp_path(d / name)).write_text(name)
    >>> sorted(p.name for p in d.iterdir())
    ['a.txt', 'b.txt']
    """
    batch = Batch()
    try:
        yield batch
        commit_all(batch.pairs, batch.removals)
    except BaseException:
        batch.discard()
        raise
