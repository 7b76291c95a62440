"""Sweeps on a real Dask LocalCluster (two worker processes on loopback): bit-identical to an in-process run, resumable, refusals recorded."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from conftest import ROOT, TEMPLATES

from wgcad.errors import OutputError
from wgcad.sweep.runner import plan_batch, run_sweep
from wgcad.sweep.spec import parse_spec
from wgcad.sweep.store import Store
from wgcad.sweep.tasks import columns_of

distributed = pytest.importorskip("distributed")
D4 = str(TEMPLATES / "d4_discrete.toml")


def _spec(seed=5, samples=6):
    # a grid of two generator deformations x random errors; the rigid run-out is normal about 5 um
    # with sd 10 um, so about a third of the draws are negative amplitudes the design rules refuse
    return parse_spec(
        {
            "sweep": {"name": "dask test", "design": D4, "samples": samples, "seed": seed},
            "figures": {
                "record": ["ke_pp_arcsec", "lost_motion_min_arcsec", "min_clearance_um"],
                "audit_step_deg": 1.0,
            },
            "parameters": {
                "generator": {"w0_coef": {"grid": [1.05, 1.1]}},
                "imperfections": {
                    "rigid_runout_um": {"distribution": "normal", "mean": 5.0, "sd": 10.0},
                    "flex_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 20.0},
                    "flex_runout_phase_deg": {"distribution": "uniform", "lo": 0.0, "hi": 360.0},
                },
            },
            "limits": {"ke_pp_arcsec": {"max": 30.0}},
        }
    )


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None, silence_logs=40
    )
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("ref")
    info = run_sweep(_spec(), out, workers=0, batch=5)
    assert info.computed == 12 and not info.stopped_early
    # in process: this process's resident memory after the first and the last task
    assert list(info.worker_rss_mb) == [os.getpid()] and all(x > 0 for x in info.worker_rss_mb[os.getpid()])
    return _read(out, _spec())


def _read(out, spec):
    pl = spec.payload()
    return Store(out, pl["fingerprint"], columns_of(pl), spec.total).read()


def _same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        if a[k].dtype == object:
            assert list(a[k]) == list(b[k]), k
        else:
            # bit for bit: the same bytes, NaNs included
            assert a[k].tobytes() == b[k].tobytes(), k


def test_dask_run_is_bit_identical_to_in_process(client, reference, tmp_path):
    info = run_sweep(_spec(), tmp_path, client=client)  # grain measured: probe task, then planned batches
    assert info.computed == 12 and info.workers == 2 and info.sample_s > 0 and info.overhead_s > 0
    # each worker process's resident memory after its first and its latest task (benchmarks/montecarlo.py)
    assert 1 <= len(info.worker_rss_mb) <= 2 and os.getpid() not in info.worker_rss_mb
    assert all(x > 0 for v in info.worker_rss_mb.values() for x in v)
    _same(_read(tmp_path, _spec()), reference)
    # a different grain and completion order: still the same bits
    out2 = tmp_path / "b"
    run_sweep(_spec(), out2, client=client, batch=1)
    _same(_read(out2, _spec()), reference)


def test_a_running_scheduler_by_address(client, reference, tmp_path):
    # --scheduler tcp://HOST:PORT: the runner connects its own client to an existing scheduler
    info = run_sweep(_spec(), tmp_path, scheduler=client.scheduler.address, batch=4)
    assert info.executor.startswith("Dask scheduler tcp://127.0.0.1:") and info.computed == 12
    _same(_read(tmp_path, _spec()), reference)


def test_refused_samples_are_recorded_not_fatal(reference):
    st = reference["status"]
    refused = st == "refused"
    assert refused.any() and (st == "ok").any() and not (st == "failed").any()
    neg = reference["imperfections.rigid_runout_um"] < 0
    np.testing.assert_array_equal(refused, neg)  # exactly the negative amplitudes, with the rule as reason
    assert all(r.startswith("imperfections.rigid_runout_um: must be in [0,") for r in reference["reason"][refused])
    assert np.isnan(reference["ke_pp_arcsec"][refused]).all() and np.isfinite(reference["ke_pp_arcsec"][~refused]).all()


def test_shared_data_is_scattered_under_fresh_keys(client, tmp_path, monkeypatch):
    # a dict scattered as is keeps its own keys as the futures' names ('design', 'ke_table', ...): a second run
    # on the same client then asks for keys the scheduler is still releasing from the first ('lost dependencies',
    # seen once in CI on the resume below). One future per run, under a key no run shares.
    keys = []
    scatter = client.scatter

    def spy(data, **kw):
        futs = scatter(data, **kw)
        keys.extend([f.key for f in futs] if isinstance(futs, list) else [futs])
        return futs

    monkeypatch.setattr(client, "scatter", spy)
    for k in range(2):
        run_sweep(_spec(), tmp_path / str(k), client=client, batch=3, max_chunks=1)
    assert len(keys) == 2 and all(isinstance(k, str) for k in keys) and keys[0] != keys[1], keys
    assert not set(keys) & set(_spec().payload()), keys


def test_resume_computes_only_the_missing_chunks(client, reference, tmp_path):
    first = run_sweep(_spec(), tmp_path, client=client, batch=2, max_chunks=2)
    assert first.stopped_early and first.computed == 4
    pl = _spec().payload()
    store = Store(tmp_path, pl["fingerprint"], columns_of(pl), 12)
    assert len(store.done_ranges()) == 2 and sum(b - a for a, b in store.missing()) == 8
    done_before = {p: os.stat(store.chunks / p).st_mtime_ns for p in os.listdir(store.chunks)}
    # a killed writer's temporary file (a pid that cannot exist) is swept, never read as a chunk
    (store.chunks / ".chunk-000000004-000000006.parquet.999999999-0123456789ab.tmp").write_bytes(b"half")
    second = run_sweep(_spec(), tmp_path, client=client, batch=3)
    assert second.skipped == 4 and second.computed == 8
    for p, t in done_before.items():  # the chunks of the first run were not rewritten
        assert os.stat(store.chunks / p).st_mtime_ns == t
    assert not [f for f in os.listdir(store.chunks) if f.endswith(".tmp")]
    _same(_read(tmp_path, _spec()), reference)
    third = run_sweep(_spec(), tmp_path, client=client)
    assert third.computed == 0 and third.skipped == 12


def test_resume_after_kill_9(reference, tmp_path):
    # a real kill: the CLI in process mode, one sample per chunk, SIGKILL once two chunks are on disk
    spec_file = tmp_path / "s.toml"
    spec_file.write_text(
        f'[sweep]\nname = "dask test"\ndesign = "{D4}"\nsamples = 6\nseed = 5\n'
        '[figures]\nrecord = ["ke_pp_arcsec", "lost_motion_min_arcsec", "min_clearance_um"]\naudit_step_deg = 1.0\n'
        "[parameters.generator.w0_coef]\ngrid = [1.05, 1.1]\n"
        '[parameters.imperfections.rigid_runout_um]\ndistribution = "normal"\nmean = 5.0\nsd = 10.0\n'
        '[parameters.imperfections.flex_runout_um]\ndistribution = "uniform"\nlo = 0.0\nhi = 20.0\n'
        '[parameters.imperfections.flex_runout_phase_deg]\ndistribution = "uniform"\nlo = 0.0\nhi = 360.0\n'
        "[limits]\nke_pp_arcsec = { max = 30.0 }\n"
    )
    out = tmp_path / "o"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [
        sys.executable,
        "-m",
        "wgcad",
        "sweep",
        str(spec_file),
        "--workers",
        "0",
        "--batch",
        "1",
        "--out",
        str(out),
        "--no-plots",
    ]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    chunks = out / "chunks"
    t0 = time.monotonic()
    while time.monotonic() - t0 < 60:
        if chunks.is_dir() and len([f for f in os.listdir(chunks) if f.startswith("chunk-")]) >= 2:
            break
        time.sleep(0.02)
    p.send_signal(signal.SIGKILL)
    p.wait()
    n_done = len([f for f in os.listdir(chunks) if f.startswith("chunk-")])
    assert 2 <= n_done < 12
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert f"{12 - n_done} samples computed, {n_done} already stored" in r.stdout
    _same(_read(out, _spec()), reference)


def test_another_spec_in_the_same_folder_is_refused(reference, tmp_path):
    run_sweep(_spec(samples=1), tmp_path, workers=0)
    with pytest.raises(OutputError, match="another sweep spec"):
        run_sweep(_spec(seed=6, samples=1), tmp_path, workers=0)


def test_grain_plan():
    # 0.1 s samples, 10 ms round trip: >= 10 samples for 1 s of work (overhead 1 %); the balance cap wins on small runs
    assert plan_batch(0.1, 0.01, 100_000, 2) == 10
    assert plan_batch(0.1, 0.01, 40, 2) == 5
    # very slow samples: one per task; very fast ones: 1 s of work, and never more than 30 s
    assert plan_batch(60.0, 0.01, 1000, 2) == 1
    assert plan_batch(1e-4, 0.01, 10**8, 2) == 10_000
    assert plan_batch(1e-4, 10.0, 10**8, 2) == 300_000


def test_workers_undo_the_nannys_malloc_tuning():
    # A Dask nanny spawns workers with MALLOC_TRIM_THRESHOLD_=65536, which turns glibc's adaptive mmap
    # threshold off: every large array is then a fresh mapping whose pages fault in anew (D2's KE ran at a third
    # of its speed on two workers, mostly in the kernel). run_batch resets the thresholds once per process:
    # repeated 1 MB arrays must then come from the heap, with a small fraction of the page faults. The child
    # gets a worker's environment (the nanny's single-threaded BLAS too).
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import resource, sys, numpy as np
        if sys.argv[1] == "fix":
            from wgcad.sweep.tasks import _allocator
            _allocator()
        a = np.ones(1 << 17)  # warm-up: the heap grows once
        del a
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(40):
            a = np.ones(1 << 17)  # 1 MB, every page touched
            del a
        print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
    """)
    import os

    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    faults = {}
    for mode in ("plain", "fix"):
        out = subprocess.run([sys.executable, "-c", code, mode], env=env, capture_output=True, text=True, check=True)
        faults[mode] = int(out.stdout.strip())
    if faults["plain"] < 40 * 100:
        pytest.skip(f"this allocator does not fault in every array anew ({faults['plain']} faults): nothing to undo")
    assert faults["fix"] < 0.1 * faults["plain"], faults


def _summary_only(spec, out):
    """What `wgcad sweep --summary-only` reads: every chunk, checked against the spec."""
    from wgcad.sweep.sampling import chunk_check

    pl = spec.payload()
    return Store(out, pl["fingerprint"], columns_of(pl), spec.total).open().read(check=chunk_check(pl))


@pytest.fixture()
def folder(tmp_path):
    out = tmp_path / "o"
    run_sweep(_spec(), out, workers=0, batch=4)  # chunks [0, 4), [4, 8), [8, 12)
    return out


def test_a_truncated_chunk_is_named(folder):
    p = sorted((folder / "chunks").iterdir())[1]
    p.write_bytes(p.read_bytes()[:100])
    with pytest.raises(OutputError, match=f"{p.name}: damaged chunk"):
        _summary_only(_spec(), folder)


def test_a_folder_named_like_a_chunk_is_named(folder):
    (folder / "chunks" / "chunk-000000012-000000013.parquet").mkdir()
    with pytest.raises(OutputError, match="outside this sweep|not a regular file"):
        _summary_only(_spec(), folder)
    (folder / "chunks" / "chunk-000000012-000000013.parquet").rmdir()
    (folder / "chunks" / "chunk-000000002-000000003.parquet").mkdir()
    with pytest.raises(OutputError, match="not a regular file"):
        _summary_only(_spec(), folder)


def test_an_overlapping_chunk_is_refused_not_counted_twice(folder):
    # before, "12 of 6 samples stored" entered the yield and its interval
    src = folder / "chunks" / "chunk-000000004-000000008.parquet"
    dup = folder / "chunks" / "chunk-000000004-000000006.parquet"
    import pyarrow.parquet as pq

    pq.write_table(pq.read_table(src).slice(0, 2), dup)
    with pytest.raises(OutputError, match="hold the same samples"):
        _summary_only(_spec(), folder)
    with pytest.raises(OutputError, match="hold the same samples"):
        run_sweep(_spec(), folder, workers=0)  # a resume refuses it too


def test_a_chunk_of_another_spec_is_refused(folder, tmp_path):
    other = tmp_path / "other"
    run_sweep(_spec(seed=6), other, workers=0, batch=4)
    name = "chunk-000000004-000000008.parquet"
    (folder / "chunks" / name).write_bytes((other / "chunks" / name).read_bytes())
    with pytest.raises(OutputError, match="another spec"):
        _summary_only(_spec(), folder)


def test_a_sweep_record_that_is_not_an_object_is_refused(folder, capsys):
    (folder / "sweep.json").write_text("[]")
    with pytest.raises(OutputError, match="not a sweep record"):
        _summary_only(_spec(), folder)
