"""Work on a second core: a job handed to another thread and its result waited for.

GEOS releases the GIL in its vectorised queries and numpy in its larger
loops, so on two cores a batch cut in halves measured on two threads
(:func:`in_halves`, :func:`wgcad.clearance.distance.pair_distance`) takes
less wall time; each pair is measured alone, so the figures are the same.
(A whole stage beside another gains nothing: the audit's entry gap and
backlash run beside its search took the same 93 ms in all, the Python
between the calls holding the GIL.) Built on ``threading`` alone
(``concurrent.futures`` would load ``logging`` and ``traceback``, ~3 ms of
every command's start).
A process forked after the helper started (a sweep's worker) has none of
its parent's threads and starts its own.
"""

from __future__ import annotations

import os
import threading
from collections import deque

import numpy as np

__all__ = ["CORES", "SPLIT", "Job", "helper", "in_halves"]


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


#: cores this process may run on
CORES = _cores()
#: pairs per call from which :func:`in_halves` cuts the work in two
SPLIT = 96


class Job:
    """The outcome of one function run on another thread; :meth:`result` waits for it."""

    __slots__ = ("_done", "_value", "_error")

    def __init__(self):
        self._done = threading.Lock()
        self._done.acquire()
        self._value = None
        self._error: BaseException | None = None

    def run(self, fn, args) -> None:
        try:
            self._value = fn(*args)
        except BaseException as exc:  # noqa: BLE001 (handed to the waiting caller, raised there)
            self._error = exc
        finally:
            self._done.release()

    def result(self):
        """The function's value once it has returned; its exception, raised here, if it raised."""
        with self._done:
            pass
        if self._error is not None:
            raise self._error
        return self._value


class _Helper:
    """One daemon thread running the jobs handed to it in order."""

    def __init__(self, name: str):
        self.pid = os.getpid()
        self._jobs: deque = deque()
        self._ready = threading.Semaphore(0)
        self._thread = threading.Thread(target=self._work, name=name, daemon=True)
        self._thread.start()

    def _work(self) -> None:
        while True:
            self._ready.acquire()
            job, fn, args = self._jobs.popleft()
            job.run(fn, args)

    def submit(self, fn, *args) -> Job:
        job = Job()
        if threading.current_thread() is self._thread:  # a job of the helper's own would wait on itself
            job.run(fn, args)
        else:
            self._jobs.append((job, fn, args))
            self._ready.release()
        return job


_HELPER: _Helper | None = None
_HELPER_LOCK = threading.Lock()


def helper() -> _Helper:
    """This process's helper thread (started on first use, again in a forked child), running jobs in turn."""
    global _HELPER
    with _HELPER_LOCK:
        if _HELPER is None or _HELPER.pid != os.getpid():
            _HELPER = _Helper("wgcad-helper")
    return _HELPER


def in_halves(fn, arrays: tuple, shared: tuple = (), least: int | None = None) -> np.ndarray:
    """``fn(*shared, *arrays)``, the arrays (of one length along their first axis) cut in two halves measured on two
    threads when they hold ``least`` (:data:`SPLIT`) pairs or more and there are two cores; the halves' results
    concatenated."""
    n = len(arrays[0]) if np.ndim(arrays[0]) else 0
    if n < (SPLIT if least is None else least) or CORES < 2 or any(np.ndim(a) == 0 or len(a) != n for a in arrays):
        return fn(*shared, *arrays)
    h = n // 2
    job = helper().submit(fn, *shared, *(a[:h] for a in arrays))
    tail = fn(*shared, *(a[h:] for a in arrays))
    return np.concatenate([job.result(), tail])
