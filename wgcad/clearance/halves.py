"""Vectorised measurements split between two threads: shapely releases the GIL in its vectorised calls and numpy in
its large ones, so on two free cores a call over many tooth pairs takes about 0.6 of its time (the KE table's
closing rotations). Each pair is measured alone, so the halves give the same figures. (The audit's polygon passes
gained 10 ms of 0.36 s this way, for 5 % more CPU and two threads in every sweep worker: left single-threaded.)"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["SPLIT", "in_halves"]

#: pairs per call from which the work is split between two threads
SPLIT = 96
_POOL = None


def _pool():
    global _POOL
    if _POOL is None or _POOL[0] != os.getpid():  # a forked child (a sweep's worker) has none of its parent's threads
        from concurrent.futures import ThreadPoolExecutor

        _POOL = (os.getpid(), ThreadPoolExecutor(2, thread_name_prefix="wgcad-halves"))
    return _POOL[1]


def in_halves(fn, arrays: tuple, shared: tuple = ()) -> np.ndarray:
    """``fn(*shared, *arrays)``, the arrays (of one length along their first axis) cut in two halves measured on two
    threads when they hold :data:`SPLIT` pairs or more and there are two cores; the halves' results concatenated."""
    n = len(arrays[0]) if np.ndim(arrays[0]) else 0
    if n < SPLIT or (os.cpu_count() or 1) < 2 or any(np.ndim(a) == 0 or len(a) != n for a in arrays):
        return fn(*shared, *arrays)
    h = n // 2
    parts = _pool().map(lambda part: fn(*shared, *part), ([a[:h] for a in arrays], [a[h:] for a in arrays]))
    return np.concatenate(list(parts))
