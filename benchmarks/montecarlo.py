"""Benchmark of D2's tolerance Monte Carlo (templates/sweeps/d2_tolerance_sweep.toml): one sample by the KE's dominance path against the block search it replaced, in the same run, the extrapolated 10,000-sample time, and whole runs on Dask with each worker's memory.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/montecarlo.py                 # in process, 30 samples each path (~1 min)
    .venv/bin/python benchmarks/montecarlo.py --dask 2000     # and 2,000 samples on 2 workers, end to end
    .venv/bin/python benchmarks/montecarlo.py --full          # and the 10,000 samples on 2 workers

What it measures (the load average is printed with the figures; the machine may be shared):

* in this process, after the worker's shared data (drive and contact table, timed):
  samples 1..n of the spec, each computed by both paths one after the
  other (``kinematic_error`` and ``kinematic_error(reference=True)``, the
  rest of the sample alike), wall and CPU seconds; the median of the
  per-sample ratios (same load for both halves of a pair); whether every
  figure recorded is the same;
* the extrapolation ``shared data + start-up + 10,000 x t / W`` for W workers,
  from the median sample (W single-threaded workers on W free cores);
* with ``--dask N`` / ``--full``: N (10,000) samples by ``run_sweep`` on a
  LocalCluster of ``--workers`` processes, wall and worker CPU per sample, and
  each worker's resident memory after its first and after its last task
  (``RunInfo.worker_rss_mb``: flat, or the run leaks).
"""

from __future__ import annotations

import argparse
import functools
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
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as the CLI and Dask's workers run

from wgcad.accuracy import ke as K  # noqa: E402
from wgcad.sweep import tasks  # noqa: E402
from wgcad.sweep.runner import run_sweep  # noqa: E402
from wgcad.sweep.spec import load_spec  # noqa: E402

SPEC = ROOT / "templates" / "sweeps" / "d2_tolerance_sweep.toml"


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def in_process(spec, n: int) -> dict:
    pl = spec.payload()
    tasks.clear_cache()
    t = time.perf_counter()
    tasks.run_sample(pl, 0)
    shared = time.perf_counter() - t
    fast = K.kinematic_error
    paths = {"new": fast, "reference": functools.partial(fast, reference=True)}
    wall = {k: [] for k in paths}
    cpu = {k: [] for k in paths}
    rows = {k: [] for k in paths}
    try:
        for i in range(1, n + 1):
            for name in ("new", "reference") if i % 2 else ("reference", "new"):
                K.kinematic_error = paths[name]
                t, c = time.perf_counter(), time.process_time()
                rows[name].append(tasks.run_sample(pl, i))
                wall[name].append(time.perf_counter() - t)
                cpu[name].append(time.process_time() - c)
    finally:
        K.kinematic_error = fast
    same = sum(a == b for a, b in zip(rows["new"], rows["reference"]))
    return {
        "samples": n,
        "shared_data_s": round(shared, 3),
        "sample_wall_s": {k: round(statistics.median(v), 4) for k, v in wall.items()},
        "sample_cpu_s": {k: round(statistics.median(v), 4) for k, v in cpu.items()},
        "ratio_reference_over_new_wall": round(
            statistics.median(b / a for a, b in zip(wall["new"], wall["reference"])), 2
        ),
        "ratio_reference_over_new_cpu": round(
            statistics.median(b / a for a, b in zip(cpu["new"], cpu["reference"])), 2
        ),
        "samples_with_every_figure_identical": f"{same} of {n}",
    }


def cluster_start_s(workers: int) -> float:
    from distributed import Client

    from wgcad.sweep.runner import local_cluster

    t = time.perf_counter()
    cl = local_cluster(workers)
    c = Client(cl)
    c.close()
    cl.close()
    return time.perf_counter() - t


def on_dask(spec, workers: int, samples: int | None) -> dict:
    from dataclasses import replace

    if samples is not None:
        spec = replace(spec, samples=samples)
    before = load()
    with tempfile.TemporaryDirectory() as d:
        info = run_sweep(spec, d, workers=workers)
    n = info.computed
    return {
        "samples": n,
        "workers": workers,
        "wall_s": round(info.wall_s, 1),
        "batch": info.batch,
        "worker_s_per_sample": round(info.worker_s / n, 4),
        "worker_cpu_s_per_sample": round(info.worker_cpu_s / n, 4),
        "extrapolated_10000_min": round(info.wall_s * 10000 / n / 60, 2),
        "worker_rss_mb_first_last": {str(p): [round(x, 1) for x in v] for p, v in info.worker_rss_mb.items()},
        "load_before": before,
        "load_after": load(),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=30, help="in-process samples per path")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--dask", type=int, default=0, help="also this many samples on --workers workers")
    ap.add_argument("--full", action="store_true", help="also the spec's 10,000 samples on --workers workers")
    args = ap.parse_args()
    spec = load_spec(SPEC)
    out = {"machine": f"{platform.machine()} {os.cpu_count()} cpus, {platform.python_version()}", "load_before": load()}
    out["in_process"] = ip = in_process(spec, args.samples)
    start = cluster_start_s(args.workers)
    out["cluster_start_s"] = round(start, 2)
    for w in sorted({1, args.workers}):
        t = ip["shared_data_s"] + start + spec.total * ip["sample_wall_s"]["new"] / w
        tr = ip["shared_data_s"] + start + spec.total * ip["sample_wall_s"]["reference"] / w
        out[f"extrapolated_{spec.total}_on_{w}_workers_min"] = {"new": round(t / 60, 2), "reference": round(tr / 60, 2)}
    out["load_in_process"] = load()
    if args.dask:
        out["dask"] = on_dask(spec, args.workers, args.dask)
    if args.full:
        out["full"] = on_dask(spec, args.workers, None)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
