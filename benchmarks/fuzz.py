"""The long fuzz run of issue 21: every command on mutated templates and random flags, checked for what must never happen.

Run from the repository root (hours for 10,000 runs on 2 cores; not part of the test run):

    .venv/bin/python benchmarks/fuzz.py --runs 10000 --workers 2 --seed 1

Each run is one ``wgcad`` command (generate, audit, the load audit, kinematics, ke, sector, parts, sweep) on a
bundled template or sweep spec mutated in its numbers, types and structure, with flags drawn from valid and
invalid values. A run is called in-process in a worker process (a fresh pool process every 20 runs) with a
temporary output folder, under an address-space cap; the checks:

- exit code 0, 1, 2 or 4 (never 3: an internal error; never a signal);
- no traceback on stderr, and a refusal (2) or a model's refusal (4) is one line;
- nothing written on a refusal: the output folder and the JSON target absent or empty;
- no run longer than ``--timeout`` seconds (a hang), none above the memory cap (a MemoryError is exit 3).

Every run draws its inputs afresh from its own seed (the mutation values are copies: nothing one run changes reaches
another), so a run is reproduced by its seed alone. A crash of the fuzzer itself while it builds or judges a run (a
bug of the fuzzer, RecursionError included) is a finding with that seed and run index, not the end of the fuzz.

Prints a JSON line per failure (command, mutation, exit, stderr) and a summary (runs per command and exit code,
failures, wall time); progress goes to stderr every ``--progress-s`` seconds. ``--budget-s`` ends the fuzz cleanly
after that long (the runs in flight are dropped, the summary printed), as does Ctrl-C. ``tests/test_fuzz.py`` is
the short, seeded version run by the test suite; ``tests/test_fuzz_bench.py`` tests this script.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import copy
import io
import json
import math
import multiprocessing as mp
import os
import random
import resource
import shutil
import signal
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES = ROOT / "templates"
DESIGNS = sorted(TEMPLATES.glob("*.toml"))
SPECS = sorted((TEMPLATES / "sweeps").glob("*.toml"))
#: address-space cap of a worker, bytes: above the default --max-memory-mb (2 GB) with room for the interpreter
MEMORY_CAP = 4 << 30


def _is_table(v) -> bool:
    return isinstance(v, dict)


# ------------------------------------------------------------------ mutations
NUMBERS = (0, -1, 1, 2, 7, 3000, 10**6, 10**12, 10**40, -(10**40), 2**63 - 1, 0.0, -0.0, 1e-300, -1e-9, 1e-6, 0.5)
NUMBERS += (1e5, 1e9, 1e39, 1e308, -1e308, math.inf, -math.inf, math.nan)
#: the non-numbers put into a mutant: each use takes a copy (:func:`_draw`). Put in as they are, the lists and the
#: table were shared by every later run of a worker and mutated there in turn, until the table held itself
#: (``{"a": {...}}``, seed 778, run 232) and listing the mutant's tables recursed without end
OTHERS = ("", "x", "ellipse", True, False, [], [1], [[1]], {"a": 1}, ["x", 1.5])


def _draw(rng: random.Random, values):
    """A value drawn from ``values``, as a copy of its own."""
    return copy.deepcopy(rng.choice(values))


def _tables(data, path=()):
    """Every table of ``data`` with its path."""
    for k, v in data.items():
        if _is_table(v):
            yield path + (k,), v
            yield from _tables(v, path + (k,))


def mutate(data: dict, rng: random.Random) -> list[str]:
    """Mutate ``data`` in place 1-3 times; returns what was done."""
    done = []
    for _ in range(rng.randint(1, 3)):
        tabs = list(_tables(data))
        if not tabs:
            break
        path, t = rng.choice(tabs)
        keys = [k for k, v in t.items() if not _is_table(v)]
        kind = rng.choice(["scale", "number", "other", "drop_key", "add_key", "drop_table", "list_item"])
        k = rng.choice(keys) if keys else None
        where = ".".join(path) + (f".{k}" if k else "")
        if kind == "scale" and k is not None and isinstance(t[k], (int, float)) and not isinstance(t[k], bool):
            f = rng.choice([0.0, -1.0, 0.5, 0.9, 0.99, 1.01, 1.1, 2.0, 10.0, 1e3, 1e-3])
            t[k] = type(t[k])(t[k] * f) if isinstance(t[k], float) or f == int(f) else t[k] * f
            done.append(f"{where} *= {f}")
        elif kind == "number" and k is not None:
            t[k] = _draw(rng, NUMBERS)
            done.append(f"{where} = {t[k]!r}")
        elif kind == "other" and k is not None:
            t[k] = _draw(rng, OTHERS)
            done.append(f"{where} = {t[k]!r}")
        elif kind == "drop_key" and k is not None:
            del t[k]
            done.append(f"del {where}")
        elif kind == "add_key":
            t[rng.choice(["bogus", "w0", "teeth", "shift_x"])] = _draw(rng, NUMBERS + OTHERS)
            done.append(f"add key to {'.'.join(path)}")
        elif kind == "drop_table" and len(path) >= 1:
            parent = data
            for p in path[:-1]:
                parent = parent[p]
            del parent[path[-1]]
            done.append(f"del [{'.'.join(path)}]")
        elif kind == "list_item" and k is not None and isinstance(t[k], list) and t[k]:
            i = rng.randrange(len(t[k]))
            t[k][i] = _draw(rng, NUMBERS + OTHERS)
            done.append(f"{where}[{i}] = {t[k][i]!r}")
    return done


# ------------------------------------------------------------------ commands
def _pick(rng, good, bad, p_bad=0.15):
    return rng.choice(bad) if rng.random() < p_bad else rng.choice(good)


def command(rng: random.Random, design: Path, spec: Path, out: Path) -> tuple[str, list]:
    """A command line (without ``wgcad``) for one run, writing under ``out``."""
    cmd = rng.choice(["generate", "audit", "load", "kinematics", "ke", "rating", "sector", "parts", "sweep"])
    d = str(design)
    if cmd == "generate":
        args = ["generate", d, "--out", str(out / "g"), "--no-stl", "--quiet"]
        if rng.random() < 0.3:
            args += ["--generator-angle", _pick(rng, ["0", "0,15", "7.5"], ["nan", "x", "1e9,0"])]
        if rng.random() < 0.3:
            args += ["--chord-tol-um", _pick(rng, ["1", "3", "10"], ["0", "-1", "1e9", "nan"])]
    elif cmd == "audit":
        args = ["audit", d, "--json", str(out / "a.json"), "--quiet"]
        args += ["--step-deg", _pick(rng, ["1", "2", "4"], ["0", "-1", "nan", "1e-9", "100"])]
        if rng.random() < 0.3:
            args += ["--sections", _pick(rng, ["1", "3", "5"], ["0", "-2", "x", "1000"])]
        if rng.random() < 0.3:
            args.append("--no-refine")
    elif cmd == "load":
        args = ["audit", d, "--json", str(out / "l.json"), "--quiet"]
        args += ["--torque-nm", _pick(rng, ["0,500", "100", "0:1000:500"], ["-5", "nan", "1e12", "x", "0:1:0"])]
        if rng.random() < 0.3:
            args += ["--cam-offset-um", _pick(rng, ["0", "20", "40"], ["-1", "1e6", "nan"])]
    elif cmd == "kinematics":
        args = ["kinematics", d, "--out", str(out / "k")]
    elif cmd == "ke":
        args = ["ke", d, "--json", str(out / "k.json")]
        if rng.random() < 0.3:
            args += ["--per-mesh", _pick(rng, ["4", "8", "16"], ["0", "-1", "x", "100000"])]
        if rng.random() < 0.15:
            args += [
                "--torque-nm",
                _pick(rng, ["80"], ["-1", "nan"]),
                "--load-samples",
                _pick(rng, ["8", "12"], ["1", "x"]),
            ]
    elif cmd == "rating":
        args = ["rating", d, "--json", str(out / "r.json")]
        if rng.random() < 0.3:
            args += ["--speed-rpm", _pick(rng, ["500", "2000", "3000"], ["0", "-1", "nan", "1e9", "x"])]
        if rng.random() < 0.2:
            args += ["--sections", _pick(rng, ["1", "2", "3"], ["0", "x", "100"])]
    elif cmd == "sector":
        args = ["sector", d, "--out", str(out / "s"), "--no-stl"]
        args += ["--step-deg", _pick(rng, ["0.2", "0.5", "1"], ["0", "-1", "nan", "1e-7"])]
    elif cmd == "parts":
        args = [
            "parts",
            d,
            "--out",
            str(out / "p"),
            "--format",
            _pick(rng, ["dxf", "dxf,svg", "stl"], ["xyz", "", "step,bogus"]),
        ]
    else:
        args = ["sweep", str(spec), "--workers", "0", "--out", str(out / "w"), "--no-plots"]
    return cmd, args


# ------------------------------------------------------------------ one run, in a worker
def _init() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    sys.path.insert(0, str(ROOT))


def run_one(job: dict) -> dict:
    """One run (:func:`_run_one`); a crash of the fuzzer's own code in it is returned as a finding, with the
    run's seed and index, so that one bug of the fuzzer does not end the fuzz without a summary."""
    try:
        return _run_one(job)
    except Exception as e:  # noqa: BLE001 (RecursionError, MemoryError, a bug of the fuzzer: all findings)
        return crash_finding(job, e)


def crash_finding(job: dict, e: BaseException) -> dict:
    """The finding of a run the fuzzer itself could not build, run or judge."""
    import traceback

    frames = traceback.extract_tb(e.__traceback__)
    where = f"{Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else "?"
    text = " ".join(str(e).split())[:300]
    return {
        "seed": job["seed"],
        "run": job.get("run"),
        "cmd": "fuzzer",
        "code": "crash",
        "bad": [f"fuzzer crash: {type(e).__name__}: {text} at {where}"],
        "s": 0.0,
        "args": [],
    }


def _run_one(job: dict) -> dict:
    from wgcad.cli import main
    from wgcad.testing import to_toml

    rng = random.Random(job["seed"])
    tmp = Path(tempfile.mkdtemp(prefix="run-", dir=job.get("tmp")))
    try:
        design = rng.choice(DESIGNS)
        data = tomllib.loads(design.read_text())
        what = mutate(data, rng) if rng.random() < 0.8 else ["unchanged"]
        dpath = tmp / f"{design.stem}.toml"
        dpath.write_text(to_toml(data))
        spec_src = rng.choice(SPECS)
        sdata = tomllib.loads(spec_src.read_text())
        sdata["sweep"]["design"] = str(dpath)
        # a sweep's work is kept small: few samples, coarse audits (the mutations may still grow it)
        if "samples" in sdata["sweep"]:
            sdata["sweep"]["samples"] = rng.choice([2, 3])
        sdata.setdefault("figures", {})["audit_step_deg"] = 4.0
        if rng.random() < 0.5:
            what += ["spec: " + m for m in mutate(sdata, rng)]
        spath = tmp / "spec.toml"
        spath.write_text(to_toml(sdata))
        out = tmp / "out"
        cmd, args = command(rng, dpath, spath, out)
        err, sink = io.StringIO(), io.StringIO()
        t0 = time.perf_counter()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(sink):
            try:
                code = main(args)
                if code == 128 + signal.SIGTERM:
                    # Pool.terminate ending the fuzz (a budget, Ctrl-C): wgcad turned its SIGTERM into the command's
                    # clean exit, and the worker would go on waiting for work while the pool waits for it to end
                    os._exit(code)
            except SystemExit as e:  # argparse
                code = e.code if isinstance(e.code, int) else 2
            except BaseException as e:  # noqa: BLE001  (anything escaping main is what the fuzz looks for)
                code = f"escaped {type(e).__name__}: {e}"
        dt = time.perf_counter() - t0
        text = err.getvalue()
        written = sorted(str(p.relative_to(out)) for p in out.rglob("*")) if out.exists() else []
        bad = []
        if code not in (0, 1, 2, 4):
            bad.append(f"exit {code}")
        if "Traceback" in text:
            bad.append("traceback")
        if code in (2, 4) and text.strip().count("\n") > 0 and cmd != "sweep":
            bad.append("refusal not one line")
        if code in (2, 4) and written:
            bad.append(f"wrote on refusal: {written[:3]}")
        return {
            "seed": job["seed"],
            "run": job.get("run"),
            "cmd": cmd,
            "code": code,
            "bad": bad,
            "s": round(dt, 3),
            "what": what,
            "args": [a.replace(str(tmp), "TMP") for a in args],
            "stderr": text.strip()[-400:],
        }
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


#: shortest wait between two looks at a run's result, s (a --progress-s of 0 does not spin)
_POLL_S = 0.05


def _collect(pool, jobs: list, a, t0: float, tally) -> str:
    """Submit every job, take each result in order and ``tally`` it; stderr hears of the progress every
    ``a.progress_s`` seconds, also while a long run is awaited. Returns why it stopped: "done", "budget"
    (``a.budget_s`` spent: the runs in flight are dropped) or "interrupted" (Ctrl-C)."""
    pending = [(j, pool.apply_async(run_one, (j,))) for j in jobs]
    budget_end = math.inf if a.budget_s is None else t0 + a.budget_s
    next_progress = time.monotonic()
    try:
        for k, (j, r) in enumerate(pending):
            hang_at = time.monotonic() + a.timeout
            res = None
            while res is None:
                now = time.monotonic()
                if now >= next_progress:
                    tally.progress(k, len(jobs), now - t0)
                    next_progress = now + a.progress_s
                if now >= budget_end:
                    return "budget"
                if now >= hang_at:
                    res = {"seed": j["seed"], "run": j["run"], "cmd": "hang", "code": "hang", "bad": ["hang"]}
                    res["s"] = a.timeout
                    break
                try:
                    res = r.get(timeout=max(_POLL_S, min(next_progress, budget_end, hang_at) - now))
                except mp.TimeoutError:
                    continue
                except Exception as e:  # noqa: BLE001 (a result that did not come back: a finding too)
                    res = crash_finding(j, e)
            tally(res)
        tally.progress(len(jobs), len(jobs), time.monotonic() - t0)
    except KeyboardInterrupt:
        return "interrupted"
    return "done"


class _Tally:
    """The findings printed as they come (stdout, a JSON line each), the counts of the summary, progress (stderr)."""

    def __init__(self):
        self.counts = collections.Counter()
        self.runs = self.failures = self.hangs = self.crashes = 0
        self.slowest = (0.0, None)

    def __call__(self, res: dict) -> None:
        self.runs += 1
        self.counts[(res["cmd"], str(res["code"]))] += 1
        if res["s"] > self.slowest[0] and res["cmd"] != "hang":
            self.slowest = (res["s"], res["args"])
        if res["bad"]:
            self.failures += 1
            self.hangs += res["cmd"] == "hang"
            self.crashes += res["cmd"] == "fuzzer"
            print(json.dumps(res), flush=True)

    def progress(self, k: int, n: int, elapsed: float) -> None:
        line = {"progress": k, "of": n, "failures": self.failures, "hangs": self.hangs, "elapsed_s": round(elapsed)}
        print(json.dumps(line), file=sys.stderr, flush=True)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--workers", type=int, default=max(1, (os.cpu_count() or 2)))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds a run may take before it counts as a hang")
    ap.add_argument(
        "--budget-s", type=float, default=None, help="stop after this many seconds (the summary counts the runs done)"
    )
    ap.add_argument("--progress-s", type=float, default=10.0, help="seconds between progress lines on stderr")
    a = ap.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    t0 = time.monotonic()
    # every run's folder under one, removed at the end: the runs a budget or Ctrl-C cut short leave none behind
    tmp = tempfile.mkdtemp(prefix="wgcad-fuzz-")
    jobs = [{"seed": a.seed * 1_000_003 + i, "run": i, "tmp": tmp} for i in range(a.runs)]
    tally = _Tally()
    try:
        with mp.get_context("fork").Pool(a.workers, initializer=_init, maxtasksperchild=20) as pool:
            stopped = _collect(pool, jobs, a, t0, tally)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    summary = {
        "runs": a.runs,
        "runs_done": tally.runs,
        "stopped": stopped,
        "seed": a.seed,
        "workers": a.workers,
        "failures": tally.failures,
        "hangs": tally.hangs,
        "fuzzer_crashes": tally.crashes,
        "wall_s": round(time.monotonic() - t0, 1),
        "slowest_s": tally.slowest[0],
        "slowest_args": tally.slowest[1],
        "by_command_and_exit": {f"{c} {e}": n for (c, e), n in sorted(tally.counts.items())},
    }
    print(json.dumps(summary, indent=1), flush=True)


if __name__ == "__main__":
    main()
