"""A results folder (wgcad design's study, wgcad sweep's chunks) is one live run's at a time: a second run on it is
refused (exit 6, one line naming the holder's pid, nothing written); the lock goes with its process, however that
ends, so a killed run's folder is taken over.

The holder is another process that takes the lock through the same function the commands use and says so on its
stdout; it keeps the lock until its stdin closes (no sleeps)."""

import os
import signal
import subprocess
import sys

import pytest
from conftest import ROOT, TEMPLATES
from test_cli_outputs import snapshot

from wgcad.cli import main
from wgcad.errors import EXIT_BUSY
from wgcad.sweep.store import LOCK_NAME, hold_folder

ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
HOLDER = (
    "import sys\n"
    "from wgcad.sweep.store import hold_folder\n"
    "with hold_folder(sys.argv[1]):\n"
    "    print('held', flush=True)\n"
    "    sys.stdin.read()\n"
)


def _holder(folder):
    """A process holding ``folder``, returned once it holds it."""
    p = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(folder)],
        env=ENV,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = p.stdout.readline()
    if line != "held\n":
        p.kill()
        pytest.fail(f"the holder did not take the lock: {line!r} {p.stderr.read()}")
    return p


def _wgcad(*argv):
    return subprocess.run(
        [sys.executable, "-m", "wgcad", *map(str, argv)], env=ENV, capture_output=True, text=True, timeout=300
    )


@pytest.fixture
def files(tmp_path):
    req = tmp_path / "req.toml"  # no z_flex in 190..196 gives ratio 100: every candidate fails at once (exit 1)
    req.write_text(
        f'[requirements]\nbase = "{TEMPLATES / "d1_involute.toml"}"\nratio = 100.0\ntrials = 2\n'
        '[free]\n"drive.z_flex" = [190, 196]\n'
    )
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'[sweep]\nname = "lock"\ndesign = "{TEMPLATES / "d4_discrete.toml"}"\nsamples = 1\nseed = 1\n'
        '[figures]\nrecord = ["min_clearance_um"]\naudit_step_deg = 4.0\n'
        "[parameters.generator.w0_coef]\ngrid = [1.05]\n"
    )
    return req, spec


def test_a_held_folder_is_refused_by_design_and_sweep(tmp_path, files):
    req, spec = files
    out = tmp_path / "out"
    holder = _holder(out)
    try:
        before = snapshot(out)
        for argv in (["design", req, "--out", out, "--no-plots"], ["sweep", spec, "--workers", "0", "--out", out]):
            r = _wgcad(*argv)
            assert r.returncode == EXIT_BUSY == 6, r.stderr
            assert r.stderr.count("\n") == 1 and r.stderr.startswith("wgcad: error: ") and "Traceback" not in r.stderr
            assert f"pid {holder.pid}" in r.stderr and "--out" in r.stderr, r.stderr
            assert r.stdout == ""
            assert snapshot(out) == before  # nothing written: no journal, no chunks, the holder's lock untouched
    finally:
        holder.stdin.close()
        assert holder.wait(timeout=60) == 0
    assert not out.exists()  # the holder made the folder and left it empty: it went with its lock file
    # released: the next run has the folder
    assert main(["design", str(req), "--out", str(out), "--no-plots", "--quiet"]) == 1
    assert (out / "study.journal").is_file() and not (out / LOCK_NAME).exists()


def test_a_killed_holder_leaves_the_folder_free(tmp_path, files, capsys):
    """SIGKILL gives no clean-up: the lock file stays, but the kernel dropped the lock, so the next run takes it over
    (a sweep folder holding only the lock file counts as empty)."""
    _, spec = files
    out = tmp_path / "out"
    holder = _holder(out)
    holder.send_signal(signal.SIGKILL)
    holder.wait(timeout=60)
    holder.stdin.close()
    assert os.listdir(out) == [LOCK_NAME]
    assert main(["sweep", str(spec), "--workers", "0", "--out", str(out), "--no-plots", "--quiet"]) == 0
    assert (out / "sweep.json").is_file() and not (out / LOCK_NAME).exists()


def test_the_lock_is_per_run_not_per_process(tmp_path):
    """Two holds of one folder in one process conflict too (flock is per open file): a library caller running two
    searches on one folder is refused as two commands are."""
    from wgcad.errors import FolderBusyError

    with hold_folder(tmp_path / "f"):
        with pytest.raises(FolderBusyError, match=f"pid {os.getpid()}"):
            with hold_folder(tmp_path / "f"):
                pass
    assert not (tmp_path / "f").exists()  # made by the hold, left empty: removed with the lock


def test_something_else_in_the_lock_files_place_is_bad_output(tmp_path, files, capsys):
    """A folder or a symbolic link named like the lock file: one line, exit 2, the link's target never created."""
    req, _ = files
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK_NAME).mkdir()
    assert main(["design", str(req), "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot take the results folder's lock" in err
    (out / LOCK_NAME).rmdir()
    (out / LOCK_NAME).symlink_to(tmp_path / "elsewhere")
    assert main(["design", str(req), "--out", str(out), "--no-plots"]) == 2
    assert "cannot take the results folder's lock" in capsys.readouterr().err
    assert not (tmp_path / "elsewhere").exists() and sorted(os.listdir(out)) == [LOCK_NAME]
