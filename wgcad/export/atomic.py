"""Atomic file writes: write to a temporary file in the target folder, then rename it into place."""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterable, Iterator
from pathlib import Path

from wgcad.errors import OutputError

__all__ = [
    "ensure_writable_dir",
    "atomic_writer",
    "atomic_write",
    "commit_all",
    "discard_all",
    "Batch",
    "atomic_batch",
]

#: Temporary files are hidden (leading dot) and end in this suffix, so a run
#: killed with SIGKILL leaves recognisable ``.<name>.<random>.tmp`` files behind.
TEMP_SUFFIX = ".tmp"


def _reason(exc: OSError) -> str:
    """Short reason of an OS error, without the path (the caller names it)."""
    return exc.strerror or type(exc).__name__


def _new_temp(final: Path) -> str:
    """Create an empty temporary file beside ``final`` and return its path.

    ``os.open(..., 0o666)`` rather than ``tempfile.mkstemp`` so the file gets
    the usual permissions after the umask (``mkstemp`` makes it 0600, and that
    mode would survive the rename).
    """
    for _ in range(100):
        temp = final.parent / f".{final.name}.{secrets.token_hex(6)}{TEMP_SUFFIX}"
        try:
            fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return str(temp)
    raise FileExistsError(f"{final.parent}: no free temporary file name")  # pragma: no cover


def _prepare_temp(final: Path) -> str:
    """Create the folder of ``final`` and an empty temporary file beside it; OutputError if it cannot."""
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
        return _new_temp(final)
    except OSError as exc:
        raise OutputError(f"{final.parent}: output folder is not writable ({_reason(exc)})") from exc


def _remove_quietly(path: str | os.PathLike) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.remove(path)


def _fsync(path: str) -> None:
    """Flush the file to disk so the rename cannot expose an empty file after a crash."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def ensure_writable_dir(path: str | os.PathLike) -> Path:
    """Create an output folder (with parents) and check that files can be written in it.

    Call this before any expensive computation so that a run with a bad
    output folder fails before it has computed or written anything.

    Parameters
    ----------
    path : str or path-like
        The folder.

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    OutputError
        ``"<dir>: output folder is not writable (<reason>)"`` when the folder
        cannot be created, is not a folder, or a probe file cannot be created
        in it. The probe matters because ``os.access`` says yes to root even
        on a read-only mount.
    """
    folder = Path(path)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{folder}: output folder is not writable ({_reason(exc)})") from exc
    if not folder.is_dir():
        raise OutputError(f"{folder}: output folder is not writable (Not a directory)")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{folder}: output folder is not writable (Permission denied)")
    try:
        probe = _new_temp(folder / ".wgcad-write-probe")
    except OSError as exc:
        raise OutputError(f"{folder}: output folder is not writable ({_reason(exc)})") from exc
    _remove_quietly(probe)
    return folder


@contextlib.contextmanager
def atomic_writer(path: str | os.PathLike) -> Iterator[str]:
    """Context manager yielding a temporary path that is renamed onto ``path`` on success.

    The temporary file is created (empty) in the folder of ``path``, so the
    final ``os.replace`` is an atomic rename on the same file system: readers
    see either the old file or the complete new one, never a partial write.
    On any exception (including ``KeyboardInterrupt``) the temporary file is
    removed and ``path`` is left untouched. The parent folder is created if
    missing.

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
        When the temporary file cannot be created, the body raises an
        ``OSError``, or the rename fails. The message names ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_writer(d / "a.txt") as tmp:
    ...     _ = pathlib.Path(tmp).write_text("done")
    >>> (d / "a.txt").read_text()
    'done'
    """
    final = Path(path)
    temp = _prepare_temp(final)
    try:
        yield temp
        _fsync(temp)
        os.replace(temp, final)
    except OutputError:
        _remove_quietly(temp)
        raise
    except OSError as exc:
        _remove_quietly(temp)
        raise OutputError(f"{final}: cannot write file ({_reason(exc)})") from exc
    except BaseException:
        _remove_quietly(temp)
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


def commit_all(pairs: Iterable[tuple[str | os.PathLike, str | os.PathLike]]) -> None:
    """Rename several prepared temporary files onto their final names.

    Every temporary file is checked (exists, regular file) and flushed to
    disk before the first rename, so the renames only fail on a fault of the
    file system itself. Renames are atomic one by one, not as a group: if
    rename number k fails, files 1..k-1 are already in place, the remaining
    temporary files are removed, and the error says how many were committed.

    Parameters
    ----------
    pairs : iterable of (final_path, temp_path)
        Each temporary file must be in the folder of its final path (as
        :meth:`Batch.temp_path` arranges).

    Raises
    ------
    OutputError
        When a temporary file is missing or a rename fails. All temporary
        files not yet renamed are removed first.
    """
    pairs = [(Path(final), str(temp)) for final, temp in pairs]
    try:
        for final, temp in pairs:
            if not os.path.isfile(temp):
                raise OutputError(f"{final}: cannot write file (prepared temporary file {temp} is missing)")
            _fsync(temp)
    except OSError as exc:
        discard_all(temp for _, temp in pairs)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"{final}: cannot write file ({_reason(exc)})") from exc
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

    def temp_path(self, path: str | os.PathLike) -> str:
        """Create and register an empty temporary file for the final file ``path``.

        Parameters
        ----------
        path : str or path-like
            Final file name; its folder is created if missing.

        Returns
        -------
        str
            Temporary file in the same folder. Write the complete content
            there, e.g. with an exporter: ``write_dxf(batch.temp_path(p), layers)``
            (the exporter's own atomic rename onto the temporary name is harmless).

        Raises
        ------
        OutputError
            When the folder is not writable or ``path`` was registered before.
        """
        final = Path(path)
        if any(os.path.abspath(final) == os.path.abspath(f) for f, _ in self.pairs):
            raise OutputError(f"{final}: cannot write file (listed twice in one batch)")
        temp = _prepare_temp(final)
        self.pairs.append((final, temp))
        return temp


@contextlib.contextmanager
def atomic_batch() -> Iterator[Batch]:
    """Write several files so that a failure while preparing any of them writes none.

    Yields a :class:`Batch`; ask it for one temporary path per output file
    and write to those. On normal exit all are renamed into place by
    :func:`commit_all`; on any exception all temporary files are removed and
    no final file is touched.

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
    except BaseException:
        discard_all(temp for _, temp in batch.pairs)
        raise
    commit_all(batch.pairs)
