"""A study's per-process cache (wgcad/sweep/tasks.py): an entry is reused only for the inputs it was built from, so a
table that changes the elastic model ([load], [parts], [supports]) builds it again."""

import copy
import tomllib

import pytest
from conftest import TEMPLATES

from wgcad.design.schema import parse_design
from wgcad.drive import build_drive
from wgcad.sweep import tasks

TORQUES = [600.0]


def _load_figures(data, cached: bool) -> dict:
    if not cached:
        tasks.clear_cache()
    design = parse_design(copy.deepcopy(data))
    return tasks._load({"load_sections": 2}, data, design, build_drive(design), TORQUES)


@pytest.mark.parametrize(
    "table, key, value",
    [("load", "tooth_compliance", "hertz"), ("supports", "cam_radial_n_per_mm", 2e3)],
)
def test_a_table_the_elastic_model_reads_is_in_the_cache_key(table, key, value):
    # the same geometry with one input of the elastic model changed: the cached figures of the first must not be
    # returned for the second, which equals its own computation from an empty cache (the reference)
    base = tomllib.loads((TEMPLATES / "d1_involute.toml").read_text())
    other = copy.deepcopy(base)
    other.setdefault(table, {})[key] = value
    tasks.clear_cache()
    first = _load_figures(base, cached=True)
    again = _load_figures(other, cached=True)
    fresh = _load_figures(other, cached=False)
    tasks.clear_cache()
    assert again == fresh
    assert again != first  # the input changes the figures (else the test could not see a stale entry)
