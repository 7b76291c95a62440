"""SIGTERM to ``wgcad design`` on a Dask cluster: the one-line message and exit 143, the cluster's client closed
without a traceback (Client.gather left its waiting coroutines to be logged as "Task exception was never
retrieved", twice, after the message), the run's end not held up by the candidates still being judged."""

import os
import selectors
import signal
import subprocess
import sys
import time

import pytest
from conftest import ROOT, TEMPLATES
from signal_helpers import MARK

pytest.importorskip("distributed")

#: a hang guard only (seconds): nothing here is a measure of speed
HANG_S = 300

LAUNCH = (
    "import sys, signal_helpers, wgcad.synthesis.search as search\n"
    "search.evaluate = signal_helpers.marked_evaluate\n"
    "from wgcad.cli import run\n"
    "sys.argv = ['wgcad', *sys.argv[1:]]\n"
    "run()\n"
)


def _read_until(p, mark: str) -> str:
    """The command's stderr up to the first line ``mark`` (or its end, if it ends first)."""
    sel = selectors.DefaultSelector()
    sel.register(p.stderr, selectors.EVENT_READ)
    fd = p.stderr.fileno()
    text = b""
    deadline = time.monotonic() + HANG_S
    while mark.encode() not in text:
        if not sel.select(timeout=max(0.0, deadline - time.monotonic())):
            p.kill()
            pytest.fail(f"no candidate started within {HANG_S} s: {text.decode()[-500:]}")
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        text += chunk
    return text.decode()


def test_sigterm_mid_search_is_one_line_and_closes_the_cluster(tmp_path):
    req = tmp_path / "req.toml"  # every candidate passes the ratio and is audited: seconds each, 8 in all
    req.write_text(
        f'[requirements]\nbase = "{TEMPLATES / "d1_involute.toml"}"\nratio = 100.0\nobjective = "min_clearance"\n'
        'trials = 8\n[free]\n"flexspline.thinning" = [0.0, 0.05]\n'
    )
    out = tmp_path / "out"
    p = subprocess.Popen(
        [sys.executable, "-c", LAUNCH, "design", str(req), "--workers", "2", "--out", str(out), "--no-plots"],
        env={**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(ROOT / "tests")])},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        before = _read_until(p, MARK)
        assert MARK in before, f"the command ended before judging a candidate: {before[-500:]}"
        p.send_signal(signal.SIGTERM)
        so, se = p.communicate(timeout=HANG_S)
    finally:
        if p.poll() is None:
            p.kill()
    err = "\n".join(line for line in (before + se.decode()).splitlines() if line != MARK)
    assert p.returncode == 128 + signal.SIGTERM, err
    assert "Traceback" not in err and "Task exception" not in err and "never retrieved" not in err, err
    assert err.strip().splitlines()[-1] == (
        "wgcad: stopped by SIGTERM; temporary files removed, no file half-written"
    ), err
    assert err.count("wgcad:") == 1, err
    assert so == b""
