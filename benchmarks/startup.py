"""Start-up benchmark: whole-process wall time of ``wgcad audit`` against the in-process audit, and where the rest goes.

Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/startup.py          # best of 7
    .venv/bin/python benchmarks/startup.py -n 15    # steadier on a busy machine

For each bundled template it measures

* the whole process, ``python -m wgcad audit TEMPLATE --quiet`` (no plots),
  spawn to exit, as a user waits for it;
* the same command in-process (``wgcad.cli.main``, modules already imported):
  the work itself;

and their ratio. Then the import chain of ``audit`` as whole-process times
of ``python -c "import a, b, ..."`` with one more module each row, so the
difference between rows is what that module adds (cold, in the order audit
imports them). Times are best-of-N wall clock; the machine's load average is
printed with them because other jobs on a 2-core machine change them.
Then the whole-process figures issue 22 sets goals for (exact and polygon audit, generate, the KE of
d2_imperfect, the part set with STEP and its peak memory) against a bare ``import numpy, shapely`` of the same
run. Writes output/bench/startup.md and startup.csv.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
OUT = ROOT / "output" / "bench"
TEMPLATES = sorted((ROOT / "templates").glob("*.toml"))

# What `wgcad audit` imports, heaviest dependencies first in the order the code reaches them
# (clearance.distance -> shapely; numpy everywhere). scipy is not on the audit path any more
# (laws/ellipse.py and profiles/measure.py import it only where an elliptic integral or a
# root is needed, which a default audit does not), so it has no row. Each row adds one.
CHAIN = [
    ("python itself", []),
    ("+ wgcad.cli (argument parsing)", ["wgcad.cli"]),
    ("+ numpy", ["numpy"]),
    ("+ shapely", ["shapely"]),
    ("+ the rest of wgcad.audit (the engine, the design schema)", ["wgcad.audit", "wgcad.cli.audit"]),
]


def env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def wall(cmd: list[str], n: int) -> tuple[float, float]:
    """Best-of-n wall time of a whole process, spawn to exit, and its CPU time (user + system) in that run.

    The CPU time is the steadier figure when other jobs share the machine:
    waiting for a core does not count in it.
    """
    best, cpu = float("inf"), float("nan")
    for _ in range(n):
        t = time.perf_counter()
        p = subprocess.Popen(cmd, env=env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(p.pid, 0)
        dt = time.perf_counter() - t
        p.returncode = os.waitstatus_to_exitcode(status)
        if p.returncode not in (0, 1):
            raise SystemExit(f"{' '.join(cmd)} failed ({p.returncode})")
        if dt < best:
            best, cpu = dt, usage.ru_utime + usage.ru_stime
    return best, cpu


def peak_mib(cmd: list[str]) -> float | None:
    """The command's largest resident size, MiB, as GNU time reports it (None without /usr/bin/time).

    Not from this process's own ``wait4``: a child forked from this process (grown by the in-process audits)
    starts with this process's resident size as its high-water mark, which ``exec`` keeps."""
    if not os.path.exists("/usr/bin/time"):
        return None
    p = subprocess.run(["/usr/bin/time", "-f", "%M", *cmd], env=env(), capture_output=True, text=True)
    return int(p.stderr.strip().splitlines()[-1]) / 1024.0


def in_process(template: Path, n: int) -> float:
    """Best-of-n time of the same command inside this process, modules already imported."""
    from wgcad.cli import main

    main(["audit", str(template), "--quiet"])  # warm: imports, caches
    best = float("inf")
    for _ in range(n):
        t = time.perf_counter()
        main(["audit", str(template), "--quiet"])
        best = min(best, time.perf_counter() - t)
    return best


def _goals(py: str, n: int) -> list[dict]:
    """The whole-process figures issue 22 sets goals for, each with the bare import's time of the same run."""
    import tempfile

    bare, bare_cpu = wall([py, "-c", "import numpy, shapely"], n)
    d1, d2i = str(ROOT / "templates" / "d1_involute.toml"), str(ROOT / "templates" / "d2_imperfect.toml")
    out = [
        {
            "command": "python -c 'import numpy, shapely'",
            "wall_s": bare,
            "cpu_s": bare_cpu,
            "ratio": 1.0,
            "peak_mib": None,
            "goal": "the yardstick",
            "met": True,
        }
    ]
    with tempfile.TemporaryDirectory() as tmp:
        cases = [
            (
                "wgcad audit d1_involute --quiet (exact)",
                [py, "-m", "wgcad", "audit", d1, "--quiet"],
                n,
                "<= 2.5x",
                lambda w, r, p: r <= 2.5,
            ),
            (
                "wgcad audit d1_involute --quiet --no-refine",
                [py, "-m", "wgcad", "audit", d1, "--quiet", "--no-refine"],
                n,
                "(polygons)",
                None,
            ),
            (
                "wgcad generate d1_involute",
                [py, "-m", "wgcad", "generate", d1, "--out", f"{tmp}/g", "--quiet"],
                n,
                "<= 3x",
                lambda w, r, p: r <= 3.0,
            ),
            ("wgcad ke d2_imperfect", [py, "-m", "wgcad", "ke", d2i], n, "< 2 s", lambda w, r, p: w < 2.0),
            (
                "wgcad parts d1_involute --format dxf,svg,stl,3mf,step",
                [py, "-m", "wgcad", "parts", d1, "--format", "dxf,svg,stl,3mf,step", "--out", f"{tmp}/p", "--quiet"],
                min(n, 3),
                "< 8 s, < 300 MiB",
                lambda w, r, p: w < 8.0 and p < 300.0,
            ),
        ]
        for label, cmd, reps, goal, ok in cases:
            w, c = wall(cmd, reps)
            peak = [peak_mib(cmd)]
            out.append(
                {
                    "command": label,
                    "wall_s": w,
                    "cpu_s": c,
                    "ratio": w / bare,
                    "peak_mib": peak[0],
                    "goal": goal,
                    "met": True
                    if ok is None
                    else bool(ok(w, w / bare, peak[0] if peak[0] is not None else float("inf"))),
                }
            )
            print(
                f"{label:60s} {w:6.3f} s (cpu {c:6.3f} s) {w / bare:5.2f}x bare, peak {peak[0]:5.0f} MiB  goal {goal}",
                flush=True,
            )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=7, help="repetitions; the best is kept (default 7)")
    args = ap.parse_args(argv)
    n = args.n
    py = sys.executable
    load0 = os.getloadavg()
    rows = []
    for t in TEMPLATES:
        whole, cpu = wall([py, "-m", "wgcad", "audit", str(t), "--quiet"], n)
        inside = in_process(t, n)
        rows.append(
            {
                "template": t.stem,
                "whole_process_s": whole,
                "whole_process_cpu_s": cpu,
                "in_process_s": inside,
                "ratio": whole / inside,
                "start_up_s": whole - inside,
            }
        )
        print(
            f"{t.stem:14s} whole {whole:6.3f} s (cpu {cpu:6.3f} s)  in-process {inside:6.3f} s  ratio {whole / inside:5.2f}",
            flush=True,
        )
    chain, mods = [], []
    for label, add in CHAIN:
        mods = mods + add
        code = "import " + ", ".join(mods) if mods else "pass"
        w, c = wall([py, "-c", code], n)
        chain.append({"step": label, "whole_process_s": w, "whole_process_cpu_s": c})
    prev = None
    for row in chain:
        row["adds_s"] = None if prev is None else row["whole_process_s"] - prev
        prev = row["whole_process_s"]
        adds = "" if row["adds_s"] is None else f"  adds {row['adds_s']:6.3f} s"
        print(
            f"{row['step']:60s} {row['whole_process_s']:6.3f} s (cpu {row['whole_process_cpu_s']:6.3f} s){adds}",
            flush=True,
        )
    goals = _goals(py, n)
    load1 = os.getloadavg()

    OUT.mkdir(parents=True, exist_ok=True)
    with open(OUT / "startup.csv", "w", newline="") as fp:
        w = csv.DictWriter(fp, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    md = [
        f"# wgcad audit start-up (best of {n})",
        "",
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
        f"load average {load0[0]:.2f} before, {load1[0]:.2f} after",
        "",
        "`python -m wgcad audit TEMPLATE --quiet` (no plots): whole process against the same command in-process",
        "",
        "| template | whole process, s | its CPU time, s | in-process, s | ratio | start-up (difference), s |",
        "|---|---|---|---|---|---|",
    ]
    md += [
        f"| {r['template']} | {r['whole_process_s']:.3f} | {r['whole_process_cpu_s']:.3f} | {r['in_process_s']:.3f} "
        f"| {r['ratio']:.2f} | {r['start_up_s']:.3f} |"
        for r in rows
    ]
    md += [
        "",
        'Import chain of `audit`: whole-process time of `python -c "import ..."`, one module more per row',
        "",
        "| step | whole process, s | its CPU time, s | adds (wall), s |",
        "|---|---|---|---|",
    ]
    for r in chain:
        adds = "" if r["adds_s"] is None else f"{r['adds_s']:.3f}"
        md.append(f"| {r['step']} | {r['whole_process_s']:.3f} | {r['whole_process_cpu_s']:.3f} | {adds} |")
    md += [
        "",
        'Whole-process goals (issue 22): each command against a bare `python -c "import numpy, shapely"` in the same '
        "run (best of N wall, the parts run best of 3; peak: one more run under GNU time)",
        "",
        "| command | whole process, s | CPU, s | x bare import | peak, MiB | goal | met |",
        "|---|---|---|---|---|---|---|",
    ]
    for g in goals:
        peak = "" if g["peak_mib"] is None else f"{g['peak_mib']:.0f}"
        met = "yes" if g["met"] else "NO"
        md.append(
            f"| {g['command']} | {g['wall_s']:.3f} | {g['cpu_s']:.3f} | {g['ratio']:.2f} | {peak} | {g['goal']} | {met} |"
        )
    (OUT / "startup.md").write_text("\n".join(md) + "\n")
    print(f"wrote {OUT / 'startup.md'} and startup.csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
