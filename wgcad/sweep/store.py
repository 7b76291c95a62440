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

import csv
import io
import json
import os
import re
from pathlib import Path

from ..errors import OutputError

__all__ = ["Store", "have_pyarrow"]

_NAME = re.compile(r"^chunk-(\d{9})-(\d{9})\.(parquet|csv)$")


def have_pyarrow() -> bool:
    try:
        import pyarrow  # noqa: F401
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        return False
    return True


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
        from ..atomic import atomic_write, ensure_writable_dir, remove_stale_temps

        meta = self.folder / "sweep.json"
        if meta.exists():
            try:
                old = json.loads(meta.read_text())
            except (OSError, ValueError) as e:
                raise OutputError(f"{meta}: unreadable sweep record ({e}); choose another --out") from None
            if old.get("fingerprint") != self.fingerprint:
                raise OutputError(
                    f"{self.folder}: holds the results of another sweep spec (fingerprint {old.get('fingerprint')}, "
                    f"this spec {self.fingerprint}); choose another --out or remove the folder"
                )
            if old.get("format") != self.fmt:
                raise OutputError(f"{self.folder}: its chunks are {old.get('format')}, this run would write {self.fmt}")
        elif self.folder.exists() and any(self.folder.iterdir()):
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
        """Sample ranges ``[a, b)`` of the chunks present, sorted."""
        out = []
        if not self.chunks.is_dir():
            return out
        for f in os.listdir(self.chunks):
            m = _NAME.match(f)
            if m and m.group(3) == self.fmt:
                out.append((int(m.group(1)), int(m.group(2))))
        return sorted(out)

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
        from ..atomic import atomic_write

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
    def read(self) -> dict:
        """All chunks present, concatenated and sorted by sample: column -> numpy array (text columns as object arrays)."""
        import numpy as np

        parts = [self._decode(self.path(a, b)) for a, b in self.done_ranges()]
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
        import numpy as np

        if self.fmt == "parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            t = pq.read_table(path)
            out = {}
            for c in self.columns:
                col = t.column(c)
                if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
                    out[c] = np.asarray(col.to_pylist(), dtype=object)
                else:
                    out[c] = col.to_numpy()
            return out
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        head = rows[0]
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
