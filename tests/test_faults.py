"""Faults under the commands: a Dask worker killed mid-sweep, the scheduler lost, the disk full, the output folder
turning read-only, the command itself killed (SIGKILL) while it writes. What must hold each time: a one-line error
(no traceback), nothing half-written under a final name, the earlier outputs intact, and a re-run that completes
(the sweep to the same bits, nothing counted twice; the temporary files a killed run left removed).

The disk faults need a file system of their own: a small tmpfs mounted in the test (root only; skipped with the
reason otherwise). Every fault is made to happen at a point the test chooses (a hook in the child process, a
callback of the run), never by racing a sleep."""

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest
from conftest import ROOT, TEMPLATES

from wgcad.sweep.runner import ClusterError, run_sweep
from wgcad.sweep.spec import parse_spec
from wgcad.sweep.store import Store
from wgcad.sweep.tasks import columns_of

D1 = TEMPLATES / "d1_involute.toml"
D4 = TEMPLATES / "d4_discrete.toml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def wgcad(*args, hook: str = "", timeout: float = 300) -> subprocess.CompletedProcess:
    """``python -m wgcad ARGS`` in a child process, with ``hook`` (Python source) run first in that process."""
    code = f"{hook}\nimport sys\nfrom wgcad.cli import run\nsys.argv = ['wgcad', *{list(map(str, args))!r}]\nrun()\n"
    return subprocess.run([sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=timeout)


def one_line_error(r: subprocess.CompletedProcess, code: int, *words: str) -> None:
    assert r.returncode == code, (r.returncode, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("wgcad: error: "), r.stderr
    assert "Traceback" not in r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


def snapshot(folder: Path) -> dict:
    """Every file under ``folder`` (hidden ones too): its relative path and the hash of its bytes (of a JSON document,
    of its content but the run time, ``elapsed_s``, the one figure a re-run does not repeat)."""

    def digest(p: Path) -> str:
        data = p.read_bytes()
        if p.suffix == ".json" and not p.name.startswith("."):
            doc = json.loads(data)  # a half-written document fails here
            if isinstance(doc, dict):
                doc.get("settings", {}).pop("elapsed_s", None)
                doc.pop("elapsed_s", None)
            data = json.dumps(doc, sort_keys=True).encode()
        return hashlib.sha256(data).hexdigest()

    return {
        str(p.relative_to(folder)): digest(p) for p in sorted(folder.rglob("*")) if p.is_file() and p.suffix != ".tmp"
    }


def temps(folder: Path) -> list:
    return [p.name for p in folder.rglob("*.tmp")]


# --------------------------------------------------------------------------- a file system of the test's own
def _mount_refusal() -> str | None:
    """Why a tmpfs cannot be mounted here (None: it can)."""
    if os.geteuid() != 0:
        return f"mounting a tmpfs needs root (running as uid {os.geteuid()})"
    if shutil.which("mount") is None or shutil.which("umount") is None:
        return "no mount/umount command"
    with tempfile.TemporaryDirectory() as d:
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", d], capture_output=True, text=True)
        if r.returncode:
            return f"mount -t tmpfs is refused here ({r.stderr.strip()})"
        subprocess.run(["umount", d], check=True)
    return None


_REFUSAL = []


@pytest.fixture
def disk(tmp_path):
    """A 16 MB tmpfs at ``tmp_path/disk`` for the test (D1's generate and parts files take ~5 MB each)."""
    if not _REFUSAL:
        _REFUSAL.append(_mount_refusal())
    if _REFUSAL[0]:
        pytest.skip(_REFUSAL[0])
    mnt = tmp_path / "disk"
    mnt.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", str(mnt)], check=True)
    yield mnt
    subprocess.run(["umount", "-l", str(mnt)], check=True)


def fill(mnt: Path, leave: int) -> Path:
    """Take all of the disk's free space but ``leave`` bytes (a file of zeros); its path."""
    st = os.statvfs(mnt)
    filler = mnt / "filler"
    with open(filler, "wb") as f:
        f.truncate(0)
        f.write(b"\0" * max(0, st.f_bavail * st.f_frsize - leave))
    return filler


def remount(mnt: Path, mode: str) -> None:
    subprocess.run(["mount", "-o", f"remount,{mode}", str(mnt)], check=True)


# --------------------------------------------------------------------------- the disk full
@pytest.mark.parametrize(
    "command, first, second",
    [
        # a re-run with one more generator angle: a larger set of files than the first run's
        (["generate", D1], [], ["--generator-angle", "0"]),
        (["parts", D1, "--format", "dxf,svg,stl"], [], ["--generator-angle", "0"]),
    ],
    ids=["generate", "parts"],
)
def test_a_full_disk_is_one_line_and_leaves_the_earlier_files(disk, command, first, second):
    out = disk / "out"
    r = wgcad(*command, "--out", out, "--quiet", *first)
    assert r.returncode == 0, r.stderr
    before = snapshot(out)
    fill(disk, 1 << 20)  # 1 MB left: less than one STL
    r = wgcad(*command, "--out", out, "--quiet", *second)
    one_line_error(r, 2, "cannot write file", "No space left on device")
    # the message names the file the user asked for, not a temporary name
    assert ".tmp" not in r.stderr
    assert snapshot(out) == before and not temps(out)


def _spec_text(samples: int = 3) -> str:
    # two W0 values x random flexspline run-outs on D4: ~0.3-1 s a sample
    return textwrap.dedent(
        f"""\
        [sweep]
        name = "fault test"
        design = "{D4}"
        samples = {samples}
        seed = 5
        [figures]
        record = ["ke_pp_arcsec", "min_clearance_um"]
        audit_step_deg = 2.0
        [parameters.generator.w0_coef]
        grid = [1.05, 1.1]
        [parameters.imperfections.flex_runout_um]
        distribution = "uniform"
        lo = 0.0
        hi = 20.0
        """
    )


def _spec(samples: int = 3):
    import tomllib

    return parse_spec(tomllib.loads(_spec_text(samples)))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The sweep computed in process, without Dask: what every faulted run must end with, bit for bit."""
    out = tmp_path_factory.mktemp("ref")
    info = run_sweep(_spec(), out, workers=0, batch=1)
    assert info.computed == 6
    return _read(out)


def _read(out):
    pl = _spec().payload()
    return Store(out, pl["fingerprint"], columns_of(pl), _spec().total).read()


def _same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        if a[k].dtype == object:
            assert list(a[k]) == list(b[k]), k
        else:
            assert a[k].tobytes() == b[k].tobytes(), k


def _chunks(out: Path) -> list:
    return sorted(p.name for p in (out / "chunks").iterdir() if p.name.startswith("chunk-"))


def test_a_full_disk_stops_a_sweep_with_its_chunks_kept_and_it_resumes(disk, reference, tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(_spec_text())
    out = disk / "sweep"
    filler = fill(disk, 4 * 4096)  # room for the record and two or three chunks (a page each)
    r = wgcad("sweep", spec, "--workers", "0", "--batch", "1", "--out", out, "--no-plots")
    one_line_error(r, 2, "cannot write file", "No space left on device")
    kept = _chunks(out)
    assert 1 <= len(kept) < 6 and not temps(out)
    filler.unlink()
    r = wgcad("sweep", spec, "--workers", "0", "--batch", "1", "--out", out, "--no-plots")
    assert r.returncode == 0, r.stderr
    assert f"{6 - len(kept)} samples computed, {len(kept)} already stored" in r.stdout
    _same(_read(out), reference)


# --------------------------------------------------------------------------- the output folder turned read-only
def test_an_output_folder_turned_read_only_mid_run(disk):
    out = disk / "out"
    r = wgcad("generate", D1, "--out", out, "--quiet", "--no-stl")
    assert r.returncode == 0, r.stderr
    before = snapshot(out)
    # the file system goes read-only once the run has its DXF's temporary file written, before the STL
    hook = (
        "import subprocess, wgcad.export.files.drive as m\n"
        "_w = m.write_stl\n"
        "def write_stl(*a, **k):\n"
        f"    subprocess.run(['mount', '-o', 'remount,ro', {str(disk)!r}], check=True)\n"
        "    return _w(*a, **k)\n"
        "m.write_stl = write_stl\n"
    )
    r = wgcad("generate", D1, "--out", out, "--quiet", hook=hook)
    remount(disk, "rw")
    one_line_error(r, 2, "Read-only file system")
    assert ".tmp" not in r.stderr
    # the final names hold the earlier run's bytes; the temporary files a read-only disk kept are the next run's
    left = temps(out)
    assert {k: v for k, v in snapshot(out).items() if not k.endswith(".tmp")} == before
    r = wgcad("generate", D1, "--out", out, "--quiet")
    assert r.returncode == 0, r.stderr
    assert not temps(out), left
    assert (out / "d1_involute_rigid.stl").stat().st_size > 0


def test_a_sweep_folder_turned_read_only_mid_run_keeps_its_chunks_and_resumes(disk, reference):
    # in process: once the first chunk is stored the disk goes read-only; the next chunk's write is the run's
    # one error (OutputError, exit 2 in the CLI), the stored chunk stays, and the run resumes once it is writable
    from wgcad.errors import OutputError

    out = disk / "sweep"
    flipped = []

    def progress(done, total, stage):
        if done >= 1 and not flipped:
            remount(disk, "ro")
            flipped.append(done)

    try:
        with pytest.raises(OutputError, match="Read-only file system") as e:
            run_sweep(_spec(), out, workers=0, batch=1, progress=progress)
    finally:
        remount(disk, "rw")
    assert "\n" not in str(e.value) and ".tmp" not in str(e.value)
    kept = _chunks(out)
    assert len(kept) == 1 and kept[0].startswith("chunk-000000000-000000001.")
    info = run_sweep(_spec(), out, workers=0, batch=1)
    assert info.skipped == 1 and info.computed == 5
    assert not temps(out)
    _same(_read(out), reference)


# --------------------------------------------------------------------------- SIGKILL while writing
def _kill_at(call: str, n: int) -> str:
    """A hook that SIGKILLs the process at the ``n``-th call of ``call`` (``os.replace``: a rename into place;
    ``_fsync``: a temporary file complete, before any rename of its batch)."""
    mod, name = call.rsplit(".", 1)
    return (
        f"import os, signal, {mod} as _m\n"
        f"_f, _n = _m.{name}, [0]\n"
        "def _hooked(*a, **k):\n"
        "    _n[0] += 1\n"
        f"    if _n[0] == {n}:\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
        "    return _f(*a, **k)\n"
        f"_m.{name} = _hooked\n"
    )


KILLS = [
    # generate: its batch of DXF, report and manifest, killed at the first flush of a complete temporary file (the
    # DXF's), before any rename; parts: killed between the renames of its batch (each file complete, old or new)
    (
        "generate",
        ["generate", D1, "--no-stl", "--out", "{out}"],
        ["--chord-tol-um", "3"],
        "wgcad.atomic.writes._fsync",
        1,
    ),
    ("parts", ["parts", D1, "--format", "dxf,svg", "--out", "{out}"], ["--chord-tol-um", "3"], "os.replace", 4),
    # audit: its JSON, killed at its rename
    (
        "audit",
        ["audit", D1, "--step-deg", "5", "--sections", "1", "--json", "{out}/d1.json"],
        ["--chord-tol-um", "3"],
        "os.replace",
        1,
    ),
]


def _args(command, out):
    return [str(a).replace("{out}", str(out)) for a in command]


@pytest.mark.parametrize(
    "name, command, other, call, n", KILLS, ids=[f"{k[0]}-{k[3].rsplit('.', 1)[1]}-{k[4]}" for k in KILLS]
)
def test_sigkill_while_writing_leaves_only_complete_files_and_the_next_run_cleans_up(
    tmp_path, name, command, other, call, n
):
    # the files of a clean run of each configuration, to judge every file the killed run leaves
    new, old = tmp_path / "new", tmp_path / "old"
    for folder, extra in ((new, []), (old, other)):
        folder.mkdir()
        r = wgcad(*_args(command, folder), "--quiet", *extra)
        assert r.returncode in (0, 1), r.stderr
    out = tmp_path / "out"
    shutil.copytree(old, out)
    r = wgcad(*_args(command, out), "--quiet", hook=_kill_at(call, n))
    assert r.returncode == -signal.SIGKILL, (r.returncode, r.stderr)
    versions = {"new": snapshot(new), "old": snapshot(old)}
    for k, h in snapshot(out).items():
        if k.endswith(".tmp"):
            continue
        # every final name holds one run's complete file: the earlier run's or the killed run's
        assert h in (versions["new"].get(k), versions["old"].get(k)), k
    left = temps(out)
    if call.endswith("_fsync"):
        assert left, "killed with its temporary files written, none was found"
    r = wgcad(*_args(command, out), "--quiet")
    assert r.returncode in (0, 1), r.stderr
    assert not temps(out), left
    assert snapshot(out) == versions["new"]


# --------------------------------------------------------------------------- a Dask worker killed, the scheduler lost
@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None, silence_logs=50
    )
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_a_worker_killed_mid_sweep_the_run_completes_to_the_same_bits(client, reference, tmp_path):
    # once the first chunk is stored, one worker is killed (SIGKILL) while tasks are still out: the nanny starts
    # another, the scheduler hands the lost task out again (retries=1) and the run ends as the in-process one, each
    # sample stored once
    pids = set(client.run(os.getpid).values())
    killed = []

    def progress(done, total, stage):
        if done >= 1 and not killed:
            pid = min(pids)
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    info = run_sweep(_spec(), tmp_path, client=client, batch=1, progress=progress)
    assert killed and info.computed == 6 and info.chunks_written == 6 and not info.stopped_early
    assert len(_chunks(tmp_path)) == 6
    _same(_read(tmp_path), reference)
    client.wait_for_workers(2, timeout=60)
    assert killed[0] not in set(client.run(os.getpid).values())  # the killed one was replaced


def test_a_lost_scheduler_is_a_clear_error_and_the_store_resumes(reference, tmp_path):
    sched_file, out = tmp_path / "scheduler.json", tmp_path / "sweep"
    sched = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--scheduler-file",
            str(sched_file),
        ],
        env=ENV,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    worker = None
    try:
        worker = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "distributed.cli.dask_worker",
                "--scheduler-file",
                str(sched_file),
                "--nthreads",
                "1",
            ],
            env=ENV,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        from distributed import Client

        with Client(scheduler_file=str(sched_file), timeout="60s") as c:
            c.wait_for_workers(1, timeout=60)
            address = c.scheduler.address

        def progress(done, total, stage):
            if done >= 1 and sched.poll() is None:
                sched.send_signal(signal.SIGKILL)
                sched.wait()

        with pytest.raises(ClusterError, match="run again to resume") as e:
            run_sweep(_spec(), out, scheduler=address, batch=1, progress=progress)
        assert "\n" not in str(e.value)
    finally:
        for p in (worker, sched):
            if p is not None and p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
    kept = _chunks(out)
    assert 1 <= len(kept) < 6
    info = run_sweep(_spec(), out, workers=0, batch=1)
    assert info.skipped == len(kept) and info.computed == 6 - len(kept)
    _same(_read(out), reference)
    json.loads((out / "sweep.json").read_text())  # the record is whole
