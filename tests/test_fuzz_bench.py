"""benchmarks/fuzz.py, the long fuzz run: every run's inputs its own, the fuzzer's own crashes reported as findings,
a time budget that ends the fuzz with its summary, progress on stderr."""

import copy
import importlib.util
import json
import multiprocessing
import os
import random
import subprocess
import sys
import tomllib

import pytest
from conftest import ROOT

from wgcad.testing import to_toml


@pytest.fixture(scope="module")
def fuzz():
    spec = importlib.util.spec_from_file_location("wgcad_fuzz_bench", ROOT / "benchmarks" / "fuzz.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # the pool's workers find its functions by this name
    spec.loader.exec_module(mod)
    yield mod
    del sys.modules[spec.name]


def _containers(value):
    if isinstance(value, dict):
        yield value
        for v in value.values():
            yield from _containers(v)
    elif isinstance(value, list):
        yield value
        for v in value:
            yield from _containers(v)


def test_runs_share_no_input(fuzz):
    """The mutations of seed 778's first 600 runs, one after the other in one process as a pool worker runs them:
    the shared value lists stay as they were and no mutant holds one of their lists or tables. Before, the table of
    OTHERS went into mutants, took a key holding itself at run 232 and the next listing of tables recursed without
    end (RecursionError, the fuzz gone without a summary)."""
    numbers, others = copy.deepcopy(fuzz.NUMBERS), copy.deepcopy(fuzz.OTHERS)
    shared = {id(c) for v in fuzz.NUMBERS + fuzz.OTHERS for c in _containers(v)}
    texts = {p: p.read_text() for p in fuzz.DESIGNS + fuzz.SPECS}
    for i in range(600):
        rng = random.Random(778 * 1_000_003 + i)
        for path in (rng.choice(fuzz.DESIGNS), rng.choice(fuzz.SPECS)):
            data = tomllib.loads(texts[path])
            fuzz.mutate(data, rng)
            assert not shared & {id(c) for c in _containers(data)}, i
            to_toml(data)  # what a run writes next: a table holding itself recursed here too
    assert repr(fuzz.NUMBERS) == repr(numbers) and fuzz.OTHERS == others


def test_a_crash_of_the_fuzzer_is_a_finding(fuzz, monkeypatch):
    def broken(*a, **k):
        raise RecursionError("maximum recursion depth exceeded")

    monkeypatch.setattr(fuzz, "command", broken)
    res = fuzz.run_one({"seed": 778002566, "run": 232})
    assert res["seed"] == 778002566 and res["run"] == 232 and res["cmd"] == "fuzzer"
    (bad,) = res["bad"]
    assert bad.startswith("fuzzer crash: RecursionError: maximum recursion depth exceeded at ")


def _canned(job):
    """A run's result without running anything: run 2 is a crash of the fuzzer; run 0 waits until run 1 has started
    (an event shared by the forked workers), so the fuzz is seen waiting for a run."""
    if job["run"] == 0:
        assert STARTED.wait(timeout=300)  # a hang guard: run 1 starts as soon as the second worker does
    if job["run"] == 1:
        STARTED.set()
    if job["run"] == 2:
        return {**job, "cmd": "fuzzer", "code": "crash", "bad": ["fuzzer crash: RecursionError"], "s": 0.0, "args": []}
    return {**job, "cmd": "audit", "code": 0, "bad": [], "s": 0.01, "args": ["audit"]}


STARTED = multiprocessing.get_context("fork").Event()


def test_the_summary_counts_findings_and_progress_goes_to_stderr(fuzz, monkeypatch, capsys):
    monkeypatch.setattr(fuzz, "run_one", _canned)  # the forked workers inherit it
    STARTED.clear()
    fuzz.main(["--runs", "6", "--workers", "2", "--seed", "3", "--progress-s", "1e9"])
    out, err = capsys.readouterr()
    finding, summary = out.split("\n", 1)
    assert json.loads(finding)["run"] == 2
    doc = json.loads(summary)
    assert doc["runs_done"] == 6 and doc["stopped"] == "done" and doc["failures"] == 1 and doc["fuzzer_crashes"] == 1
    assert doc["by_command_and_exit"] == {"audit 0": 5, "fuzzer crash": 1}
    # one line as the fuzz starts, one at its end (1e9 s between lines)
    progress = [json.loads(line) for line in err.splitlines()]
    assert [p["progress"] for p in progress] == [0, 6] and progress[-1]["failures"] == 1


def _canned_waiting(job):
    """Run 0 returns only once the fuzz has said twice, while it waited, that no run is done yet."""
    if job["run"] == 0:
        assert STARTED.wait(timeout=300)  # a hang guard
    return {**job, "cmd": "audit", "code": 0, "bad": [], "s": 0.01, "args": ["audit"]}


def test_progress_comes_while_a_run_is_awaited(fuzz, monkeypatch, capsys):
    """A run that lasts: progress lines still come every --progress-s (0 here: at every look at the awaited run);
    before, a line came only as a result arrived (every 500 runs)."""
    monkeypatch.setattr(fuzz, "run_one", _canned_waiting)
    said = []
    progress = fuzz._Tally.progress

    def watched(self, k, n, elapsed):
        progress(self, k, n, elapsed)
        said.append(k)
        if said.count(0) == 2:
            STARTED.set()  # what run 0 waits for

    monkeypatch.setattr(fuzz._Tally, "progress", watched)
    STARTED.clear()
    fuzz.main(["--runs", "3", "--workers", "1", "--progress-s", "0"])
    lines = [json.loads(line)["progress"] for line in capsys.readouterr().err.splitlines()]
    assert lines == said and said.count(0) >= 2 and said[-1] == 3 and said == sorted(said)


def test_the_budget_ends_the_fuzz_with_its_summary(fuzz, capsys):
    """A budget of 0 s: no run can be waited for; the fuzz stops at once and still prints its summary."""
    fuzz.main(["--runs", "4", "--workers", "1", "--budget-s", "0"])
    doc = json.loads(capsys.readouterr().out)
    assert doc["stopped"] == "budget" and doc["runs"] == 4 and doc["runs_done"] == 0


STOPPER = """
import importlib.util, multiprocessing, sys, threading
spec = importlib.util.spec_from_file_location("wgcad_fuzz_bench", sys.argv[1])
fuzz = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = fuzz
spec.loader.exec_module(fuzz)
import wgcad.cli
from wgcad.cli.common import Terminated, signals_raise
inside = multiprocessing.get_context("fork").Event()

def command(args):  # a command that never ends by itself, with wgcad's SIGTERM handling (a clean exit, 143)
    try:
        with signals_raise():
            inside.set()
            threading.Event().wait()
    except Terminated as e:
        return 128 + e.signum

def progress(self, k, n, elapsed):  # the budget is looked at once a run is in its command
    inside.wait()

wgcad.cli.main = command
fuzz._Tally.progress = progress
fuzz.main(["--runs", "2", "--workers", "1", "--budget-s", "0"])
"""


def test_a_budget_stop_ends_a_run_inside_a_command():
    """The budget ends while a run is inside a wgcad command, which turns SIGTERM into its own clean exit: the fuzz
    still ends with its summary (seed 778 with --budget-s 480 took 678 s and two SIGKILLs to end: Pool.terminate's
    SIGTERM left its workers waiting for work, and the pool waiting for them)."""
    r = subprocess.run(
        [sys.executable, "-c", STOPPER, str(ROOT / "benchmarks" / "fuzz.py")],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        timeout=120,  # a hang guard
    )
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["stopped"] == "budget" and doc["runs_done"] == 0
