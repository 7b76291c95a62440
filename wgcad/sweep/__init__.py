"""Sweeps: tolerance Monte Carlo and design studies over many samples of a design, on Dask (spec, sampling, tasks, store, runner, summary).

Only the spec and sampling are imported here; the runner imports Dask when it runs.
"""

from .sampling import sample_values, split_index  # noqa: F401
from .spec import Parameter, SweepSpec, load_spec, parse_spec  # noqa: F401

__all__ = ["Parameter", "SweepSpec", "load_spec", "parse_spec", "sample_values", "split_index"]
