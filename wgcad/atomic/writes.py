"""Atomic file writes: write to a temporary file in the target folder, then rename it into place (the checks of the targets live in :mod:`wgcad.atomic.targets`)."""

from __future__ import annotations

import contextlib
import errno
import os
import signal
from collections.abc import Iterable, Iterator
from pathlib import Path

from wgcad.errors import OutputError

from .targets import check_target, not_a_folder, os_reason
from .temps import new_temp, remove_quietly, remove_stale_temps, shown_name

__all__ = ["atomic_writer", "atomic_write", "commit_all", "discard_all", "Batch", "atomic_batch"]

# Signals deferred while a batch renames its files into place, so that an
# interrupt never leaves half of a batch committed.
_DEFERRED = tuple(s for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP")) if s is not None)


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
        return new_temp(final)
    except OSError as exc:
        if isinstance(exc, NotADirectoryError):
            reason = not_a_folder(final.parent)
        elif exc.errno == errno.ENOENT and final.parent.is_dir():
            reason = f"the file system refuses new files there ({os_reason(exc)})"
        else:
            reason = os_reason(exc)
        raise OutputError(f"{final.parent}: output folder is not writable ({reason})") from exc


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
        remove_quietly(temp)
        _remove_empty_dirs(created)
        raise
    except OSError as exc:
        remove_quietly(temp)
        _remove_empty_dirs(created)
        raise OutputError(f"{shown_name(final)}: cannot write file ({os_reason(exc)})") from exc
    except BaseException:
        remove_quietly(temp)
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
        remove_quietly(temp)


def commit_all(
    pairs: Iterable[tuple[str | os.PathLike, str | os.PathLike]], remove: Iterable[str | os.PathLike] = ()
) -> None:
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
        raise OutputError(f"{final}: cannot write file ({os_reason(exc)})") from exc
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
                    f"{final}: cannot write file ({os_reason(exc)}); {k} of {len(pairs)} files were already written"
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
