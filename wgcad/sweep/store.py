"""The result store of a sweep: a folder of chunk files (Parquet, or CSV without pyarrow), each written atomically as its task finishes.

Layout of ``OUT``::

    sweep.json                       what the results are of (spec fingerprint, columns)
    chunks/chunk-000000000-000000050.parquet   samples [0, 50)
    ...

A chunk appears complete or not at all (written to a temporary file in the
same folder, then renamed), so after an interruption the chunks present are
exactly the samples done: :meth:`Store.missing` gives the rest. The chunk
grain may differ between runs (ranges, not fixed numbers, name the files).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import re
from pathlib import Path

import numpy as np

from ..atomic import atomic_write, ensure_writable_dir, remove_stale_temps
from ..errors import FolderBusyError, InputFileError, OutputError
from ..userfiles import read_user_text

__all__ = ["Store", "have_pyarrow", "hold_folder", "LOCK_NAME"]

#: the lock file of a results folder (a sweep's or a design study's), held while a run writes there
LOCK_NAME = ".wgcad.lock"

#: a sweep record is a few hundred bytes
_MAX_META_BYTES = 1 << 20
_NAME = re.compile(r"^chunk-(\d{9})-(\d{9})\.(parquet|csv)$")


def have_pyarrow() -> bool:
    try:
        import pyarrow  # noqa: F401
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        return False
    return True


@contextlib.contextmanager
def hold_folder(folder):
    """Hold the results folder ``folder`` (created if missing) for the run inside the ``with``: an exclusive
    ``fcntl.flock`` on its :data:`LOCK_NAME` file, which records the holder's pid.

    The kernel drops the lock when its process ends, however it ends, so a killed run leaves no stale lock: the
    next run takes the folder over. A folder another live run holds is refused at once
    (:class:`~wgcad.errors.FolderBusyError`, naming its pid), before anything is written. On the way out the lock
    file goes, and so does a folder this call created that stayed empty. Where ``fcntl`` is missing (Windows) the
    folder is not locked.
    """
    folder = Path(folder)
    made = [p for p in (folder, *folder.parents) if not p.exists()]
    ensure_writable_dir(folder)
    try:
        import fcntl
    except ImportError:  # pragma: no cover (no flock on Windows)
        fcntl = None
    path = folder / LOCK_NAME
    fd = None
    try:
        try:
            fd = _lock(path, folder) if fcntl is not None else None
        except FolderBusyError:
            raise
        except OSError as e:  # a folder, link or unwritable file in the lock file's place, a full disk
            raise OutputError(f"{path}: cannot take the results folder's lock ({e.strerror or e})") from None
        yield folder
    finally:
        if fd is not None:
            with contextlib.suppress(OSError):
                os.unlink(path)  # before the lock is dropped: a waiting run then finds no file, or its own
            os.close(fd)
        for p in made:
            with contextlib.suppress(OSError):
                p.rmdir()  # only an empty folder this run made


def _lock(path: Path, folder: Path) -> int:
    """The open, locked lock file ``path`` with this process's pid in it (:func:`hold_folder`)."""
    import fcntl

    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 32).decode("ascii", "replace").strip()
            os.close(fd)
            who = f"pid {holder}" if holder.isdigit() else "another process"
            raise FolderBusyError(
                f"{folder}: another wgcad run ({who}) is writing there and holds {LOCK_NAME}; wait for it to end or "
                "choose another --out"
            ) from None
        except BaseException:
            os.close(fd)
            raise
        # the holder that released the lock just before removed its file: lock the file now in place, not that one
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path, follow_symlinks=False))
        except FileNotFoundError:
            same = False
        if same:
            try:
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
            except BaseException:
                os.close(fd)
                raise
            return fd
        os.close(fd)


class Store:
    """Chunks of one sweep's results in ``folder``.

    Parameters
    ----------
    folder : path
    fingerprint : str
        :meth:`SweepSpec.fingerprint`: a folder holding another spec's results is refused.
    columns : list of str
    fmt : "parquet", "csv" or None (Parquet when pyarrow imports)
    """

    def __init__(self, folder, fingerprint: str, columns: list, total: int, fmt: str | None = None, name: str = ""):
        self.folder = Path(folder)
        self.chunks = self.folder / "chunks"
        self.fingerprint = fingerprint
        self.columns = list(columns)
        self.total = int(total)
        self.fmt = fmt or ("parquet" if have_pyarrow() else "csv")
        self.name = name

    # -- the folder ----------------------------------------------------------
    def open(self) -> Store:
        """Create the folder (or check that it holds this spec's results) and write ``sweep.json``."""
        meta = self.folder / "sweep.json"
        if meta.exists() or meta.is_symlink():
            try:
                old = json.loads(read_user_text(meta, "sweep record", _MAX_META_BYTES, "JSON"))
            except (InputFileError, ValueError) as e:
                raise OutputError(f"{meta}: unreadable sweep record ({e}); choose another --out") from None
            if not isinstance(old, dict):
                raise OutputError(f"{meta}: not a sweep record (a JSON object); choose another --out")
            if old.get("fingerprint") != self.fingerprint:
                raise OutputError(
                    f"{self.folder}: holds the results of another sweep spec (fingerprint {old.get('fingerprint')}, "
                    f"this spec {self.fingerprint}); choose another --out or remove the folder"
                )
            if old.get("format") != self.fmt:
                raise OutputError(f"{self.folder}: its chunks are {old.get('format')}, this run would write {self.fmt}")
        elif self.folder.exists() and any(p.name != LOCK_NAME for p in self.folder.iterdir()):
            raise OutputError(f"{self.folder}: not empty and not a sweep folder (no sweep.json); choose another --out")
        ensure_writable_dir(self.chunks)
        remove_stale_temps(self.chunks)  # temporaries of a killed run
        doc = {
            "fingerprint": self.fingerprint,
            "name": self.name,
            "columns": self.columns,
            "total": self.total,
            "format": self.fmt,
        }
        atomic_write(meta, (json.dumps(doc, indent=2) + "\n").encode())
        return self

    def done_ranges(self) -> list[tuple[int, int]]:
        """Sample ranges ``[a, b)`` of the chunks present, sorted.

        Raises
        ------
        OutputError
            A chunk's name that is not a regular file, a range outside ``[0, total)``, or two chunks holding the
            same samples (named, so the user can remove one: the samples are then recomputed or kept once).
        """
        out = []
        if not self.chunks.is_dir():
            return out
        for f in os.listdir(self.chunks):
            m = _NAME.match(f)
            if m and m.group(3) == self.fmt:
                a, b = int(m.group(1)), int(m.group(2))
                p = self.chunks / f
                if p.is_symlink() or not p.is_file():
                    raise OutputError(f"{p}: named like a chunk but not a regular file; remove it")
                if not 0 <= a < b <= self.total:
                    raise OutputError(f"{p}: samples [{a}, {b}) outside this sweep's [0, {self.total}); remove it")
                out.append((a, b))
        out.sort()
        for (a0, b0), (a1, b1) in zip(out, out[1:]):
            if a1 < b0:
                raise OutputError(
                    f"{self.path(a0, b0)} and {self.path(a1, b1)} hold the same samples [{a1}, {min(b0, b1)}); "
                    "remove one (its samples are computed again if missing)"
                )
        return out

    def missing(self) -> list[tuple[int, int]]:
        """Sample ranges not yet in any chunk."""
        gaps, at = [], 0
        for a, b in self.done_ranges():
            if a > at:
                gaps.append((at, a))
            at = max(at, b)
        if at < self.total:
            gaps.append((at, self.total))
        return gaps

    def path(self, a: int, b: int) -> Path:
        return self.chunks / f"chunk-{a:09d}-{b:09d}.{self.fmt}"

    # -- writing -------------------------------------------------------------
    def write(self, a: int, b: int, columns: dict) -> Path:
        """Write samples ``[a, b)`` atomically; returns the chunk's path."""
        p = self.path(a, b)
        atomic_write(p, self._encode(columns))
        return p

    def _encode(self, columns: dict) -> bytes:
        if self.fmt == "parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            arrays = {}
            for c in self.columns:
                v = columns[c]
                if c in ("status", "reason") or any(isinstance(x, str) for x in v):
                    arrays[c] = pa.array([str(x) for x in v], type=pa.string())
                elif c in ("sample", "grid_point", "draw"):
                    arrays[c] = pa.array(v, type=pa.int64())
                else:
                    arrays[c] = pa.array([float(x) for x in v], type=pa.float64())
            buf = io.BytesIO()
            pq.write_table(pa.table(arrays), buf, compression="zstd")
            return buf.getvalue()
        s = io.StringIO()
        w = csv.writer(s, lineterminator="\n")
        w.writerow(self.columns)
        n = len(columns[self.columns[0]])
        for i in range(n):
            # repr of a float round-trips exactly: a CSV sweep is as bit-exact as a Parquet one
            w.writerow(
                [
                    repr(float(columns[c][i])) if isinstance(columns[c][i], float) else columns[c][i]
                    for c in self.columns
                ]
            )
        return s.getvalue().encode()

    # -- reading -------------------------------------------------------------
    def read(self, check=None) -> dict:
        """All chunks present, concatenated and sorted by sample: column -> numpy array (text columns as object arrays).

        Every chunk is checked before use: readable, every column present, its samples those its name says;
        ``check(a, b, columns)`` may check more (the sweep's parameters: a chunk of another spec) and raises
        :class:`OutputError` naming the chunk.
        """
        parts = []
        for a, b in self.done_ranges():
            p = self.path(a, b)
            try:
                cols = self._decode(p)
            except Exception as e:  # a damaged file: whatever its reader raises
                raise OutputError(
                    f"{p}: damaged chunk ({type(e).__name__}: {str(e)[:120]}); remove it and run again to recompute "
                    "its samples"
                ) from None
            samples = cols["sample"]
            if len(samples) != b - a or not np.array_equal(samples, np.arange(a, b)):
                raise OutputError(f"{p}: does not hold samples [{a}, {b}) as its name says; remove it")
            if check is not None:
                check(a, b, cols)
            parts.append(cols)
        out = {}
        for c in self.columns:
            arrs = [p[c] for p in parts]
            text = c in ("status", "reason") or any(a.dtype == object for a in arrs)
            dtype = np.int64 if c in ("sample", "grid_point", "draw") else object if text else float
            out[c] = np.concatenate([a.astype(dtype) for a in arrs]) if arrs else np.zeros(0, dtype)
        if parts:
            order = np.argsort(out["sample"], kind="stable")
            out = {k: v[order] for k, v in out.items()}
        return out

    def _decode(self, path: Path) -> dict:
        """One chunk: column -> numpy array (object arrays for text)."""
        if self.fmt == "parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            t = pq.read_table(path)
            out = {}
            for c in self.columns:
                if c not in t.column_names:
                    raise ValueError(f"no column {c!r}")
                col = t.column(c)
                if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
                    out[c] = np.asarray(col.to_pylist(), dtype=object)
                else:
                    out[c] = col.to_numpy()
            return out
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        head = rows[0]
        missing = [c for c in self.columns if c not in head]
        if missing or any(len(r) != len(head) for r in rows[1:]):
            raise ValueError(f"columns {missing} missing or rows of unequal length")
        cols = {c: [r[head.index(c)] for r in rows[1:]] for c in self.columns}
        out = {}
        for c, v in cols.items():
            if c in ("sample", "grid_point", "draw"):
                out[c] = np.asarray([int(x) for x in v], dtype=np.int64)
            elif c in ("status", "reason"):
                out[c] = np.asarray(v, dtype=object)
            else:
                try:
                    out[c] = np.asarray([float(x) for x in v], dtype=float)
                except ValueError:  # a text parameter (generator.law)
                    out[c] = np.asarray(v, dtype=object)
        return out
