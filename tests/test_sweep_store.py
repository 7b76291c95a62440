"""The sweep result store: chunks in Parquet and in CSV read back the same bits; missing ranges; a foreign folder refused."""

import math

import numpy as np
import pytest

from wgcad.errors import OutputError
from wgcad.sweep.store import Store, have_pyarrow

COLS = [
    "sample",
    "grid_point",
    "draw",
    "generator.law",
    "imperfections.flex_runout_um",
    "ke_pp_arcsec",
    "status",
    "reason",
]


def _chunk(a, b):
    n = b - a
    rng = np.random.default_rng(a)
    return {
        "sample": list(range(a, b)),
        "grid_point": [0] * n,
        "draw": list(range(a, b)),
        "generator.law": ["disc"] * n,
        "imperfections.flex_runout_um": list(rng.normal(size=n) * 1e-3 + 1 / 3),
        "ke_pp_arcsec": [math.nan if i % 3 == 0 else float(x) for i, x in enumerate(rng.random(n) * 600)],
        "status": ["refused" if i % 3 == 0 else "ok" for i in range(n)],
        "reason": ["x.y: must be >= 0, got -1" if i % 3 == 0 else "" for i in range(n)],
    }


@pytest.mark.parametrize("fmt", ["csv"] + (["parquet"] if have_pyarrow() else []))
def test_round_trip_is_exact_and_missing_ranges(tmp_path, fmt):
    s = Store(tmp_path / fmt, "abc", COLS, 20, fmt=fmt).open()
    assert s.missing() == [(0, 20)]
    s.write(5, 9, _chunk(5, 9))
    s.write(0, 5, _chunk(0, 5))
    s.write(12, 20, _chunk(12, 20))
    assert s.missing() == [(9, 12)]
    got = s.read()
    want = {k: _chunk(0, 5)[k] + _chunk(5, 9)[k] + _chunk(12, 20)[k] for k in COLS}
    for k in COLS:
        if k in ("generator.law", "status", "reason"):
            assert list(got[k]) == want[k]
        else:
            assert got[k].tobytes() == np.asarray(want[k], dtype=got[k].dtype).tobytes(), k
    with pytest.raises(OutputError, match="another sweep spec"):
        Store(tmp_path / fmt, "other", COLS, 20, fmt=fmt).open()


def test_a_folder_with_other_files_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="not a sweep folder"):
        Store(tmp_path, "abc", COLS, 10, fmt="csv").open()
