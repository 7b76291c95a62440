"""Many load states of one drive, in fixed chunks shared among processes: a loaded KE run, an installation-angle scan
(docs/models.md 6.3).

The states of a loaded KE run are independent, but each is solved fastest warm-started from a state near it. The
run is therefore cut into chunks of :data:`CHUNK` consecutive states, each chunk starting cold and warm-starting
within itself (each state from the chunk's solved state whose inputs are nearest), and the chunks are shared among
worker processes (forked: the model is inherited, not copied). The chunks do not depend on how many processes run
them, so neither do the figures: one process and several give the same bits.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass

import numpy as np

__all__ = ["CHUNK", "StateJob", "StateRun", "solve_states", "default_workers"]

#: states a chunk warm-starts through before the next chunk starts cold (fixed: the figures must not depend on the
#: number of processes); a cold start costs about two warm ones, so 32 keep the extra work near 3 %
CHUNK = 32

#: what the worker processes read: the model and the jobs, set before the pool forks (inherited, never pickled)
_SHARED: dict = {}


@dataclass(frozen=True)
class StateJob:
    """One run of load states: the drive's errors, the torque, the mesh periods to solve at (docs/models.md 6.3)."""

    imp: object
    torque_nm: float
    periods: np.ndarray
    tol: float | None = None


@dataclass(frozen=True)
class StateRun:
    """The figures of a job's states: output rotation (rad), loaded tooth contacts, zone shares ``(n, waves)``."""

    theta: np.ndarray
    teeth: np.ndarray
    share: np.ndarray


def default_workers() -> int:
    """The processes a run may use: the cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _chunk(task):
    """Solve one chunk ``(job index, start, stop)`` of a job's states (a worker's task, or the parent's)."""
    from ..elastic import solve_load
    from .load_errors import tooth_errors

    j, a, b = task
    model, jobs = _SHARED["model"], _SHARED["jobs"]
    job = jobs[j]
    kw = {} if job.tol is None else {"tol": job.tol}
    n_w = model.drive.design.drive.waves
    theta = np.empty(b - a)
    teeth = np.empty(b - a, dtype=int)
    share = np.empty((b - a, n_w))
    solved = []  # (inputs, state) of the chunk's states so far
    for i, n in enumerate(job.periods[a:b]):
        errs, e_um, e_deg = tooth_errors(model, job.imp, int(n))
        inputs = (errs, 1e-3 * e_um * np.array([np.cos(np.radians(e_deg)), np.sin(np.radians(e_deg))]))
        warm = _nearest(model, solved, inputs)
        st = solve_load(
            model, float(job.torque_nm), e_um, e_deg, warm=warm, tooth_errors=errs, exact_report=False, **kw
        )
        solved.append((inputs, st))
        theta[i] = st.output_rotation
        c = st.contacts
        teeth[i] = int(np.count_nonzero((c["kind"] == 1) & (c["force"] > 0)))
        share[i] = st.zone_share()
    return task, theta, teeth, share


def _nearest(model, solved: list, inputs):
    """The solved state whose inputs (the teeth's errors, the cam offset) differ least from ``inputs``, the most
    recent among equals; None for the first. A run's consecutive states are not the nearest: the cam offset turns
    with the generator, a quarter turn and more between samples, while the state a generator turn earlier differs
    by the slow drift of the teeth's errors (so it starts within a few micrometres of the fixed point, not a
    hundred)."""
    if not solved:
        return None
    (turn, move), e = inputs
    lever = model.drive.r_m
    best, best_d = None, np.inf
    for (errs_j, e_j), st in reversed(solved):
        d = (
            float(np.abs(move - errs_j[1]).max())
            + lever * float(np.abs(turn - errs_j[0]).max())
            + float(np.hypot(*(e - e_j)))
        )
        if d < best_d:
            best, best_d = st, d
    return best


def solve_states(model, jobs: list, workers: int | None = None, progress=None) -> list:
    """The :class:`StateRun` of every :class:`StateJob` (module docstring). ``progress(done, total)`` counts states."""
    tasks = [
        (j, a, min(a + CHUNK, len(job.periods)))
        for j, job in enumerate(jobs)
        for a in range(0, len(job.periods), CHUNK)
    ]
    total = sum(len(job.periods) for job in jobs)
    n_w = model.drive.design.drive.waves
    out = [
        StateRun(np.empty(len(job.periods)), np.empty(len(job.periods), dtype=int), np.empty((len(job.periods), n_w)))
        for job in jobs
    ]
    workers = default_workers() if workers is None else max(1, int(workers))
    workers = min(workers, len(tasks))
    _SHARED.update(model=model, jobs=jobs)
    pool = None
    done = 0
    try:
        if workers <= 1:
            results = map(_chunk, tasks)
        else:
            import multiprocessing as mp

            pool = ProcessPoolExecutor(workers, mp_context=mp.get_context("fork"))
            results = (f.result() for f in as_completed([pool.submit(_chunk, t) for t in tasks]))
        for (j, a, b), theta, teeth, share in results:
            r = out[j]
            r.theta[a:b], r.teeth[a:b], r.share[a:b] = theta, teeth, share
            done += b - a
            if progress is not None:
                progress(done, total)
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)
        _SHARED.clear()
    return out
