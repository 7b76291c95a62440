"""What a user waits for on the loaded model, against the previous release in the same run: one elastic state, the
loaded KE with and without the installation-angle scan, the datasheet, a synthesis candidate.

Run from the repository root, with a checkout of the previous release beside it (not part of the test run):

    git worktree add /tmp/wgcad-prev <previous release>     # once
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/loaded.py --baseline /tmp/wgcad-prev
    .venv/bin/python benchmarks/loaded.py --only state,ke      # some rows, no baseline

Each row runs as a whole process (the command a user types, with this checkout or the baseline first on the path)
and reports wall and CPU seconds of the children (its worker processes included), best of ``--repeat``; the ratio
is baseline over this checkout in CPU seconds, the two alternating. The one-state row is in-process (CPU ms of a
warm state of D1 at 1000 N m, median of 21). Prints a Markdown table and writes output/bench/loaded.json.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "output" / "bench"

#: the rows: name, what, command line (after ``python -m wgcad``; ``{T}`` the checkout's own templates folder: a
#: release reads its own templates, whose tables it knows)
ROWS = [
    ("ke", "wgcad ke d2_imperfect --torque-nm 80,800", ["ke", "{T}/d2_imperfect.toml", "--torque-nm", "80,800"]),
    (
        "ke_install",
        "the same with --optimize-install-angle",
        ["ke", "{T}/d2_imperfect.toml", "--torque-nm", "80,800", "--optimize-install-angle"],
    ),
    ("rating", "wgcad rating d1_involute", ["rating", "{T}/d1_involute.toml"]),
    (
        "design",
        "wgcad design requirements/d1_ratio100 (per candidate)",
        ["design", "{T}/requirements/d1_ratio100.toml", "--workers", "1", "--out", "{OUT}"],
    ),
]


def _trials(path: Path) -> int:
    """The requirements file's trials: the design row is per candidate."""
    import tomllib

    return int(tomllib.loads(path.read_text())["requirements"]["trials"])


#: rows whose figure is per item: the whole command's time over this many (the requirements' trials)
PER = {"design": _trials(ROOT / "templates" / "requirements" / "d1_ratio100.toml")}


def _run(root: Path, argv, cwd: Path) -> tuple[float, float, int]:
    """Wall and children's CPU seconds of ``python -m wgcad argv`` with ``root`` first on the path; exit code."""
    env = {**os.environ, "PYTHONPATH": str(root), "OPENBLAS_NUM_THREADS": "1"}
    out = tempfile.mkdtemp(dir=cwd)  # a fresh study folder per run: a resumed study would skip its trials
    argv = [a.replace("{T}", str(root / "templates")).replace("{OUT}", out) for a in argv]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "wgcad", *argv], cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if r.returncode not in (0, 1):
        sys.stderr.write(f"{root}: {' '.join(argv)}: exit {r.returncode}\n{r.stderr[-2000:]}\n")
    return wall, cpu, r.returncode


def _state_ms(root: Path) -> float:
    """CPU ms of one warm elastic state of D1 at 1000 N m (median of 21), in a child with ``root`` on the path."""
    code = f"""
import sys, time, statistics
sys.path.insert(0, {str(root)!r})
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
m = build_model(build_drive(load_design({str(root / "templates" / "d1_involute.toml")!r})), 3)
w = solve_load(m, 1000.0)
ts = []
for k in range(21):
    t = time.process_time()
    solve_load(m, 1000.0 + (k % 2), warm=w)
    ts.append(time.process_time() - t)
print(1e3 * statistics.median(ts))
"""
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return float(r.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, help="a checkout of the previous release")
    ap.add_argument("--only", help="comma-separated rows: state," + ",".join(r[0] for r in ROWS))
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args(argv)
    only = None if not args.only else set(args.only.split(","))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        if only is None or "state" in only:
            cur = min(_state_ms(ROOT) for _ in range(args.repeat))
            base = min(_state_ms(args.baseline) for _ in range(args.repeat)) if args.baseline else None
            rows.append(
                {"row": "state", "what": "one elastic state, D1 at 1000 N m, warm (CPU ms)", "now": cur, "base": base}
            )
        for name, what, cmd in ROWS:
            if only is not None and name not in only:
                continue
            best, best_b = None, None
            for _ in range(args.repeat):
                if args.baseline:
                    b = _run(args.baseline, cmd, cwd)
                    best_b = b if best_b is None or b[1] < best_b[1] else best_b
                c = _run(ROOT, cmd, cwd)
                best = c if best is None or c[1] < best[1] else best
            n = PER.get(name, 1)
            rows.append(
                {
                    "row": name,
                    "what": what,
                    "now": best[0] / n,
                    "now_cpu": best[1] / n,
                    "base": None if best_b is None else best_b[0] / n,
                    "base_cpu": None if best_b is None else best_b[1] / n,
                }
            )
            print(json.dumps(rows[-1]), flush=True)
    print()
    print(f"load average at the end: {os.getloadavg()[0]:.2f} (2 cores)")
    # on a shared machine the wall time is mostly the others' load: the ratio is of CPU seconds (the state row is
    # CPU already), the wall times are shown beside it
    print("| work | now (CPU) | previous release (CPU) | ratio (CPU) | now / previous (wall) |")
    print("|---|---|---|---|---|")
    for r in rows:
        unit = "ms" if r["row"] == "state" else "s"
        now, base = r.get("now_cpu", r["now"]), r.get("base_cpu", r["base"])
        ratio = "-" if not base else f"{base / now:.2f}x"
        wall = (
            "-"
            if r["row"] == "state"
            else f"{r['now']:.1f} s / " + ("-" if r["base"] is None else f"{r['base']:.1f} s")
        )
        shown = "-" if base is None else f"{base:.2f} {unit}"
        print(f"| {r['what']} | {now:.2f} {unit} | {shown} | {ratio} | {wall} |")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "loaded.json").write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
