"""Benchmark of `wgcad sweep` on Dask: per-task overhead, tasks per second, scaling over 1, 2 and 4 workers, and D2's 10,000-sample KE tolerance Monte Carlo.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/sweep.py              # overhead, one sample's time, 1 vs 2 workers (~3 min)
    .venv/bin/python benchmarks/sweep.py --full       # and the whole 10,000-sample Monte Carlo (~15-30 min on 2 cores)

What it measures (wall-clock; the load average is printed with the figures, the
machine may be shared):

* Dask's per-task overhead: the round trip of an empty task (median of 50,
  one at a time) and the throughput of 400 empty tasks submitted at once, on
  a LocalCluster of 2 processes;
* one sample of templates/sweeps/d2_tolerance_sweep.toml in this process: the
  shared data (drive and KE contact table, built once per worker) and the
  per-sample time after it (best of 3 over 5 samples), wall and CPU (on a
  shared machine the CPU time is the process's own work);
* the same spec, N samples, on LocalClusters of 1, 2 and 4 workers (``--workers``; each started
  fresh: cluster start and the per-worker shared data included): samples/s,
  the speed-up, worker time per sample, and the share of the workers' time
  not spent computing samples (Dask, the client storing chunks, idle at the end),
  each with the cores that were free before it (cores less the 1-minute load
  average): more workers than free cores cannot scale, and the figures say so;
* tasks of 1 sample against the measured grain on the same samples: what the
  per-task overhead costs when tasks are too small;
* with --full: the 10,000 samples of the template on 2 workers, end to end, and each worker's resident
  memory after its first and its last task (benchmarks/montecarlo.py compares the KE's two paths).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from wgcad.sweep.runner import local_cluster, run_sweep  # noqa: E402
from wgcad.sweep.spec import load_spec  # noqa: E402

SPEC = ROOT / "templates" / "sweeps" / "d2_tolerance_sweep.toml"


def load() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:  # pragma: no cover
        return "?"


def overhead():
    from distributed import Client

    from wgcad.sweep.tasks import noop

    cl = local_cluster(2)
    c = Client(cl)
    try:
        c.submit(noop, -1, pure=False).result()
        rt = []
        for k in range(50):
            t = time.perf_counter()
            c.submit(noop, k, pure=False).result()
            rt.append(time.perf_counter() - t)
        t = time.perf_counter()
        futs = [c.submit(noop, k, pure=False) for k in range(400)]
        c.gather(futs)
        thr = 400 / (time.perf_counter() - t)
    finally:
        c.close()
        cl.close()
    return statistics.median(rt), thr


def in_process(spec):
    from wgcad.sweep import tasks

    pl = spec.payload()
    tasks.clear_cache()
    t = time.perf_counter()
    tasks.run_batch(pl, 0, 1)
    first = time.perf_counter() - t
    best = cpu = float("inf")
    for _ in range(3):
        t, c = time.perf_counter(), time.process_time()
        tasks.run_batch(pl, 1, 6)
        best = min(best, (time.perf_counter() - t) / 5)
        cpu = min(cpu, (time.process_time() - c) / 5)
    return first - best, best, cpu


def run(spec, workers, batch=None, samples=None):
    from dataclasses import replace

    if samples is not None:
        spec = replace(spec, samples=samples)
    with tempfile.TemporaryDirectory() as d:
        info = run_sweep(spec, d, workers=workers, batch=batch)
    return info


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=160, help="samples of each worker-count run")
    ap.add_argument(
        "--workers",
        default="1,2,4",
        help="worker counts to run (comma list; more than the cores shows oversubscription)",
    )
    ap.add_argument("--full", action="store_true", help="also the 10,000-sample Monte Carlo")
    args = ap.parse_args()
    spec = load_spec(SPEC)
    out = {"machine": f"{platform.machine()} {os.cpu_count()} cpus, {platform.python_version()}", "load_before": load()}
    rt, thr = overhead()
    out["dask_round_trip_ms"] = round(1e3 * rt, 2)
    out["dask_empty_tasks_per_s"] = round(thr, 1)
    shared, per, cpu = in_process(spec)
    out["shared_data_build_s"] = round(shared, 3)
    out["sample_s_in_process"] = round(per, 4)
    out["sample_cpu_s_in_process"] = round(cpu, 4)
    n = args.samples
    res = {}
    counts = sorted({int(x) for x in args.workers.split(",")} | {1, 2})
    for w in counts:
        before = os.getloadavg()[0]
        info = run(spec, w, samples=n)
        res[w] = info
        out[f"workers_{w}"] = {
            # what else was running: the cores not busy before the run, from the 1-minute load average
            "cores": os.cpu_count(),
            "cores_free_before": round(max(0.0, os.cpu_count() - before), 2),
            "samples": n,
            "wall_s": round(info.wall_s, 2),
            "samples_per_s": round(n / info.wall_s, 3),
            "batch": info.batch,
            "tasks_per_s": round(n / info.batch / info.wall_s, 3),
            "worker_s_per_sample": round(info.worker_s / n, 4),
            "worker_cpu_s_per_sample": round(info.worker_cpu_s / n, 4),
            "share_not_computing": round(1 - info.worker_s / (w * info.wall_s), 3),
            "load": load(),
        }
    for w in counts[1:]:
        out[f"speedup_{w}_vs_1"] = round(res[1].wall_s / res[w].wall_s, 3)
    small = run(spec, 2, batch=1, samples=n)
    out["batch_1_on_2_workers"] = {
        "wall_s": round(small.wall_s, 2),
        "tasks_per_s": round(n / small.wall_s, 2),
        "vs_measured_grain": round(small.wall_s / res[2].wall_s, 3),
        "load": load(),
    }
    rate = n / res[2].wall_s
    out["extrapolated_10000_samples_on_2_workers_min"] = round(10000 / rate / 60, 1)
    if args.full:
        info = run(spec, 2)
        out["full_10000"] = {
            "wall_s": round(info.wall_s, 1),
            "minutes": round(info.wall_s / 60, 2),
            "batch": info.batch,
            "worker_s_per_sample": round(info.worker_s / info.computed, 4),
            "worker_cpu_s_per_sample": round(info.worker_cpu_s / info.computed, 4),
            # each worker's resident memory after its first and its last task: flat, or the run leaks
            "worker_rss_mb_first_last": {str(p): [round(x, 1) for x in v] for p, v in info.worker_rss_mb.items()},
            "load": load(),
        }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
