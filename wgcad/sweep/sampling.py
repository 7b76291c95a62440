"""Samples of a sweep: grid point and random draw of sample ``i``, reproducible from the seed and the index alone.

Sample ``i`` is grid point ``g = i // samples`` (the grid parameters in the
order of the spec, the first varying slowest) and draw ``r = i % samples``.
The draw's random numbers come from ``SeedSequence(seed, spawn_key=(r,))``,
the generator ``SeedSequence(seed).spawn`` would give as its ``r``-th child:
any sample can be made alone, in any process, in any order, and gives the
same values; every grid point sees the same draws (common random numbers,
so differences between grid points are not sampling noise).
"""

from __future__ import annotations

import copy

import numpy as np

from ..errors import OutputError

__all__ = ["split_index", "sample_values", "sample_design_data", "envelope_amplitudes_um", "chunk_check"]


def split_index(i: int, samples: int, grid_shape: tuple) -> tuple[tuple, int]:
    """``(grid indices, draw)`` of sample ``i``."""
    g, r = divmod(int(i), int(samples))
    idx = np.unravel_index(g, grid_shape) if grid_shape else ()
    return tuple(int(x) for x in idx), r


def sample_values(payload: dict, i: int) -> dict:
    """``{parameter name: value}`` of sample ``i`` (floats; grid values as given, text for text keys)."""
    params = payload["parameters"]
    gidx, r = split_index(i, payload["samples"], payload["grid_shape"])
    out = {}
    gi = iter(gidx)
    rand = [p for p in params if p.random]
    if rand:
        rng = np.random.default_rng(np.random.SeedSequence(payload["seed"], spawn_key=(r,)))
        # one standard variate per random parameter, in spec order, then scaled: a parameter's value
        # does not depend on the distributions of the others
        z = rng.random(len(rand))
        zi = iter(z)
    for p in params:
        if p.kind == "grid":
            out[p.name] = p.values[next(gi)]
        elif p.kind == "uniform":
            out[p.name] = float(p.a + (p.b - p.a) * next(zi))
        else:
            from scipy.special import ndtri

            u = next(zi)
            # inverse CDF of the uniform variate (u = 0 has probability 2^-53: nudged inside)
            out[p.name] = float(p.a + p.b * ndtri(min(max(u, 2.0**-54), 1.0 - 2.0**-54)))
    return out


def sample_design_data(base: dict, params, values: dict) -> dict:
    """The design TOML dict of a sample: the base with each parameter's key set (tables created as needed)."""
    data = copy.deepcopy(base)
    for p in params:
        data.setdefault(p.table, {})[p.key] = values[p.name]
    return data


def envelope_amplitudes_um(base_spec, params) -> dict:
    """Largest value each ``[imperfections]`` amplitude takes in the sweep: the base's, or the parameter's reach.

    The KE contact table is built once per worker for these amplitudes
    (which contacts are close enough to matter grows with them), so it
    serves every sample whose amplitudes stay within them.
    """
    amp = dict(base_spec.amplitudes_um)
    for p in params:
        if p.table == "imperfections" and p.key in amp:
            amp[p.key] = max(amp[p.key], max(0.0, p.reach()))
    return amp


def chunk_check(payload: dict):
    """A check for :meth:`wgcad.sweep.store.Store.read`: a chunk's parameter columns must be the values this spec
    draws for its samples (bit for bit), so a chunk of another spec (another seed, distribution or grid) left in
    the folder is named and refused instead of entering the yield."""
    names = [p.name for p in payload["parameters"]]

    def check(a: int, b: int, cols: dict) -> None:
        for i in range(a, b):
            want = sample_values(payload, i)
            for n in names:
                got = cols[n][i - a]
                w = want[n]
                same = (
                    got == w if isinstance(w, str) else isinstance(got, (int, float, np.floating)) and float(got) == w
                )
                if not same:
                    raise OutputError(
                        f"chunk of samples [{a}, {b}): sample {i} has {n} = {got!r}, this spec draws {w!r}; the "
                        "chunk is of another spec: remove it"
                    )

    return check
