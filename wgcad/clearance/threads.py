"""Work on a second core: half of a batch handed to a helper thread (a ``concurrent.futures`` pool of one).

GEOS releases the GIL in its vectorised queries and numpy in its larger
loops, so on two cores a batch cut in halves measured on two threads
(:func:`in_halves`, :func:`wgcad.clearance.distance.pair_distance`) takes
less wall time; each pair is measured alone, so the figures are the same.
(A whole stage beside another gains nothing: the audit's entry gap and
backlash run beside its search took the same time in all, the Python
between the calls holding the GIL.)
A process forked after the pool started (a sweep's worker) has none of its
parent's threads: the fork hook forgets the parent's pool, and the child
starts its own on first use.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["CORES", "SPLIT", "pool", "in_halves"]


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


#: cores this process may run on
CORES = _cores()
#: pairs per call from which :func:`in_halves` cuts the work in two
SPLIT = 96

_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()
_ON_HELPER = threading.local()


def _mark_helper() -> None:
    _ON_HELPER.yes = True


def _forget_pool() -> None:
    # in a forked child: the parent's pool thread does not exist here, and a job queued to it would never run
    global _POOL, _POOL_LOCK
    _POOL = None
    _POOL_LOCK = threading.Lock()


os.register_at_fork(after_in_child=_forget_pool)


def pool() -> ThreadPoolExecutor:
    """This process's helper: a pool of one thread, started on first use (again in a forked child)."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = ThreadPoolExecutor(1, thread_name_prefix="wgcad-helper", initializer=_mark_helper)
    return _POOL


def in_halves(fn, arrays: tuple, shared: tuple = (), least: int | None = None) -> np.ndarray:
    """``fn(*shared, *arrays)``, the arrays (of one length along their first axis) cut in two halves measured on two
    threads when they hold ``least`` (:data:`SPLIT`) pairs or more and there are two cores; the halves' results
    concatenated. Called on the helper thread itself, it measures both halves there (queued, the first half would
    wait on the thread that waits for it)."""
    n = len(arrays[0]) if np.ndim(arrays[0]) else 0
    if (
        n < (SPLIT if least is None else least)
        or CORES < 2
        or getattr(_ON_HELPER, "yes", False)
        or any(np.ndim(a) == 0 or len(a) != n for a in arrays)
    ):
        return fn(*shared, *arrays)
    h = n // 2
    head = pool().submit(fn, *shared, *(a[:h] for a in arrays))
    tail = fn(*shared, *(a[h:] for a in arrays))
    return np.concatenate([head.result(), tail])
