"""Running a sweep on Dask: a local cluster or a given scheduler, task grain by measurement, chunks stored as tasks finish.

The client (this process) plans and stores; workers only compute
(:func:`wgcad.sweep.tasks.run_batch`). The spec goes to the workers once
(``scatter(broadcast=True)``); a task carries a sample range. Results come
back to the client, which writes each chunk atomically as it arrives, so
workers need no shared file system and an interruption loses at most the
tasks in flight.

Task grain (samples per task), unless the spec or ``--batch`` fixes it:
Dask's round trip is measured with empty tasks and one sample's time with
a probe task (the probe's samples are kept as the first chunk), then

* at least ``overhead / (0.02 t_sample)`` samples, so that Dask's overhead stays
  under 2 % of a task, and at least 1 s of work (a chunk file per second per worker);
* at most ``30 s / t_sample``: a killed run loses at most ~30 s per worker
  and the progress bar moves;
* at most ``remaining / (4 workers)``: every worker gets several tasks
  (the slowest one does not hold up the end).
"""

from __future__ import annotations

import math
import os
import statistics
import time
from dataclasses import dataclass, field

from ..errors import WgcadError
from ..extras import require
from .store import Store
from .tasks import columns_of, noop, run_batch

__all__ = ["RunInfo", "ClusterError", "run_sweep", "plan_batch", "local_cluster", "close_cluster"]


class ClusterError(WgcadError, RuntimeError):
    """The cluster failed under a sweep (a worker died twice on a task, the scheduler went away); the chunks done are kept."""

    exit_code = 4


#: Dask's share of a task's time the grain aims below
OVERHEAD_SHARE = 0.02
#: longest task aimed at, s: what a killed run loses per worker, and the progress bar's step
TASK_MAX_S = 30.0
#: tasks per worker at least (load balance at the end of the run)
TASKS_PER_WORKER = 4
#: shortest task aimed at, s: one chunk file per second per worker keeps the store's file count sane
TASK_MIN_S = 1.0


@dataclass
class RunInfo:
    """What a run did: samples computed and skipped (already stored), grain, timings."""

    total: int
    computed: int = 0
    skipped: int = 0
    chunks_written: int = 0
    batch: int = 0
    workers: int = 0
    overhead_s: float | None = None
    sample_s: float | None = None
    wall_s: float = 0.0
    worker_s: float = 0.0
    worker_cpu_s: float = 0.0
    stopped_early: bool = False
    executor: str = ""
    notes: list = field(default_factory=list)
    #: per worker process (pid), its resident memory (MB) after the first and after the latest of its tasks
    worker_rss_mb: dict = field(default_factory=dict)


def plan_batch(sample_s: float, overhead_s: float, remaining: int, workers: int) -> int:
    """Samples per task from the measured sample time and Dask round trip (module docstring)."""
    sample_s = max(sample_s, 1e-6)
    lo = math.ceil(max(overhead_s / OVERHEAD_SHARE, TASK_MIN_S) / sample_s)
    hi = min(max(1, int(TASK_MAX_S / sample_s)), max(1, math.ceil(remaining / (TASKS_PER_WORKER * max(workers, 1)))))
    return max(1, min(lo, hi))


def _ranges(gaps, batch: int):
    for a, b in gaps:
        for s in range(a, b, batch):
            yield s, min(b, s + batch)


def local_cluster(workers: int):
    """A Dask LocalCluster of ``workers`` single-threaded processes on loopback, no dashboard, and its log kept off
    the command's stderr up to errors (logging.CRITICAL): a failed task reaches the run as its future's exception,
    and what Dask logs at ERROR is its own shutdown races (a worker closing while its heartbeat is in flight logs
    "Failed to communicate with scheduler during heartbeat" with two tracebacks)."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=50,
    )


#: how long a worker of an interrupted run is given to stop before it is killed, s (the nanny's close timeout)
_ABANDON_TIMEOUT_S = 0.5


def close_cluster(cluster, interrupted: bool = False) -> None:
    """Close a cluster of :func:`local_cluster`. After an interruption (Ctrl-C, SIGTERM) the tasks still running are
    abandoned, so every worker process is stopped at once (each nanny closed with a short timeout, all together):
    a plain close first asks each busy worker to finish its task and waits up to 4 s for it (the nanny's 5 s
    timeout x 0.8) before killing it."""
    if interrupted:
        import asyncio

        async def stop_workers():
            nannies = list(cluster.workers.values())
            await asyncio.gather(*(w.close(timeout=_ABANDON_TIMEOUT_S) for w in nannies), return_exceptions=True)

        try:
            cluster.sync(stop_workers)
        except Exception:  # noqa: BLE001 (the plain close below still runs; the interruption is what matters)
            pass
    cluster.close()


def run_sweep(
    spec,
    out,
    *,
    client=None,
    scheduler: str | None = None,
    workers: int | None = None,
    batch: int | None = None,
    progress=None,
    max_chunks: int | None = None,
    fmt: str | None = None,
) -> RunInfo:
    """Compute every sample of ``spec`` not yet stored in ``out``.

    Parameters
    ----------
    client : distributed.Client, optional
        Use it (tests share one cluster); else ``scheduler`` (an address) or
        a new LocalCluster of ``workers`` processes. ``workers=0`` and no
        client nor scheduler: in this process, without Dask (the reference
        the Dask runs are tested against, and a debugging aid).
    batch : int, optional
        Samples per task; default the spec's ``batch``, else measured.
    progress : callable, optional
        ``progress(done, total, stage)`` in samples of the whole sweep.
    max_chunks : int, optional
        Stop after writing this many chunks (what a killed run leaves; tests).
    """
    if client is None and not (workers == 0 and scheduler is None):
        require("sweep")  # before anything is stored
    payload = spec.payload()
    store = Store(out, payload["fingerprint"], columns_of(payload), spec.total, fmt=fmt, name=spec.name).open()
    gaps = store.missing()
    remaining = sum(b - a for a, b in gaps)
    info = RunInfo(total=spec.total, skipped=spec.total - remaining)
    t0 = time.perf_counter()
    batch = batch or spec.batch or None

    def tick(stage):
        if progress:
            progress(info.skipped + info.computed, spec.total, stage)

    def stored(res):
        store.write(res["start"], res["stop"], res["columns"])
        info.computed += res["stop"] - res["start"]
        info.chunks_written += 1
        info.worker_s += res["compute_s"]
        info.worker_cpu_s += res.get("cpu_s", 0.0)
        if "rss_mb" in res:
            info.worker_rss_mb.setdefault(res["pid"], [res["rss_mb"], 0.0])[1] = res["rss_mb"]
        tick(f"{info.skipped + info.computed}/{spec.total} samples")
        return max_chunks is not None and info.chunks_written >= max_chunks

    tick("starting")
    if remaining == 0:
        info.executor = "none (all samples stored)"
        return info
    if client is None and scheduler is None and workers == 0:
        info.executor, info.workers = "in process (no Dask)", 1
        info.batch = batch or 64
        todo = list(_ranges(gaps, info.batch))
        for k, (a, b) in enumerate(todo):
            if stored(run_batch(payload, a, b)):
                info.stopped_early = k < len(todo) - 1
                break
        info.wall_s = time.perf_counter() - t0
        return info
    cluster = own = None
    interrupted = False
    try:
        client, own, cluster = _connect(client, scheduler, workers, info)
        info.workers = max(1, len(client.scheduler_info(n_workers=-1)["workers"]))
        # one future under a fresh key: scattering the dict itself would name each value by its dict key
        # ('design', 'ke_table', ...), and a second run on the same client (a resume) would then ask for keys
        # the scheduler is still releasing from the first: 'lost dependencies'
        [pf] = client.scatter([payload], broadcast=True, hash=False)
        gaps = list(gaps)
        if not batch:
            if _probe(client, pf, gaps, info, stored, tick):
                info.stopped_early = bool(gaps)
                return info
            batch = plan_batch(info.sample_s, info.overhead_s, sum(b - a for a, b in gaps), info.workers)
        info.batch = batch
        _collect(client, pf, gaps, batch, info, stored, spec.total)
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM / SIGHUP as the CLI raises them
        interrupted = True
        raise
    finally:
        info.wall_s = time.perf_counter() - t0
        if own is not None:
            own.close()
        if cluster is not None:
            close_cluster(cluster, interrupted)
    return info


def _connect(client, scheduler, workers, info: RunInfo):
    """``(client, client this run opened, cluster this run started)``: the given client, one to ``scheduler``, or a
    new LocalCluster of ``workers`` processes; ``info.executor`` says which."""
    if client is not None:
        info.executor = f"Dask client {getattr(client.scheduler, 'address', '')}"
        return client, None, None
    from distributed import Client

    if scheduler is not None:
        try:
            own = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as e:
            raise WgcadError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({e})") from None
        info.executor = f"Dask scheduler {scheduler}"
        return own, own, None
    n = workers or max(1, min(os.cpu_count() or 1, 64))
    cluster = local_cluster(n)
    own = Client(cluster)
    info.executor = f"Dask LocalCluster, {n} processes on loopback"
    return own, own, cluster


def _probe(client, pf, gaps: list, info: RunInfo, stored, tick) -> bool:
    """Measure Dask's round trip (empty tasks, after one to warm the connection) and one sample's time (a probe
    task of a few samples, whose first pays for the shared data), storing the probe's samples and taking them
    off ``gaps``; True when the store says stop."""
    client.submit(noop, 0, pure=False).result()
    rt = []
    for k in range(5):
        s = time.perf_counter()
        client.submit(noop, k, pure=False).result()
        rt.append(time.perf_counter() - s)
    info.overhead_s = statistics.median(rt)
    a, b = gaps[0]
    pb = min(3, b - a)
    tick("probe task (builds the shared data)")
    res = client.submit(_timed_batch, pf, a, a + pb, pure=False).result()
    ts = res.pop("sample_s")
    info.sample_s = statistics.mean(ts[1:]) if len(ts) > 1 else ts[0]
    stop = stored(res)
    gaps[0] = (a + pb, b)
    if a + pb == b:
        gaps.pop(0)
    return stop


def _collect(client, pf, gaps, batch: int, info: RunInfo, stored, total: int) -> None:
    """Submit the batches of ``gaps`` and store each result as it arrives; a failed task is a ClusterError that
    keeps what was stored; every future still pending is cancelled on the way out."""
    from distributed import as_completed

    futs = [client.submit(run_batch, pf, a, b, pure=False, retries=1) for a, b in _ranges(gaps, batch)]
    try:
        for f in as_completed(futs):
            try:
                res = f.result()
            except Exception as e:  # noqa: BLE001 - KilledWorker, lost scheduler, CommClosedError...
                raise ClusterError(
                    f"a Dask task failed ({type(e).__name__}: {' '.join(str(e).split())[:200]}); "
                    f"{info.chunks_written} chunks stored this run are kept: run again to resume"
                ) from e
            if stored(res):
                info.stopped_early = info.computed + info.skipped < total
                break
    finally:
        for f in futs:
            f.cancel()


def _timed_batch(payload, start, stop):
    """:func:`run_batch` with each sample's time (the probe task)."""
    ts = []
    cols = None
    t0, c0 = time.perf_counter(), time.process_time()
    for i in range(start, stop):
        s = time.perf_counter()
        r = run_batch(payload, i, i + 1)
        ts.append(time.perf_counter() - s)
        if cols is None:
            cols = {k: list(v) for k, v in r["columns"].items()}
        else:
            for k, v in r["columns"].items():
                cols[k].extend(v)
    return {
        "columns": cols,
        "start": start,
        "stop": stop,
        "compute_s": time.perf_counter() - t0,
        "cpu_s": time.process_time() - c0,
        "sample_s": ts,
        "built": 0,
        "pid": r["pid"],
        "rss_mb": r["rss_mb"],
    }
