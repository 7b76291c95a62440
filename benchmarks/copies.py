"""What each of wgcad's own copies of a library's job buys: its share of a command a user waits for, whole process.

docs/architecture.md's rule: a dependency's job is done by the dependency; a copy stays only where it buys
at least 10 % of a command a user waits for, measured here, and the library cannot be asked to do it cheaper.
For each copy this runs the command as shipped (A) and with the copy swapped for the library doing the same
job, imported where the job is done (B: the cheapest way to ask the library), in turn (A B A B ...), and
prints the medians of both runs' CPU seconds (user + system: time spent waiting for a core does not count, so
the steadier figure on a shared machine) and wall seconds, and the share of the command the copy buys,
``(B - A) / B`` of the CPU seconds. Run from the repository root (not part of the test run):

    .venv/bin/python benchmarks/copies.py               # 7 pairs a command
    .venv/bin/python benchmarks/copies.py -n 15 --only roots

The swaps (B):

* ``roots``: :func:`wgcad.roots.brentq` -> ``scipy.optimize.brentq``, imported inside the call (the commands
  whose profiles need a root: the double-arc and cycloidal forms);
* ``mesh``: the STL bytes written by trimesh (imported inside the call) from the same vertices and faces; the
  3MF and the checks stay wgcad's, so B is a lower bound of asking trimesh.

Writes output/bench/copies.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "output" / "bench"
T = ROOT / "templates"

_BRENTQ = """
def _brentq(f, a, b, xtol=2e-12, maxiter=200):
    from scipy.optimize import brentq
    return brentq(f, a, b, xtol=xtol, maxiter=maxiter)
wgcad.roots.brentq = _brentq
"""
_TRIMESH = """
def _stl(self, header):
    import trimesh
    return trimesh.Trimesh(self.vertices, self.faces, process=False).export(file_type="stl")
wgcad.export.formats.mesh.Mesh.stl_bytes = _stl
"""

#: copy -> (what it replaces, the module the swap patches, the swap, [(label, command line after ``wgcad``)]);
#: {out} is a scratch folder
COPIES = {
    "roots": (
        "scipy.optimize.brentq",
        "wgcad.roots",
        _BRENTQ,
        [
            ("audit d1_double_arc", ["audit", T / "d1_double_arc.toml", "--quiet"]),
            ("generate d1_double_arc", ["generate", T / "d1_double_arc.toml", "--out", "{out}", "--quiet"]),
            ("generate d1_cycloidal", ["generate", T / "d1_cycloidal.toml", "--out", "{out}", "--quiet"]),
        ],
    ),
    "mesh": (
        "trimesh's STL writer",
        "wgcad.export.formats.mesh",
        _TRIMESH,
        [
            ("generate d1_involute", ["generate", T / "d1_involute.toml", "--out", "{out}", "--quiet"]),
            (
                "parts d1_involute (stl, 3mf)",
                ["parts", T / "d1_involute.toml", "--out", "{out}", "--format", "stl,3mf", "--quiet"],
            ),
        ],
    ),
}


def _script(module: str, swap: str, argv: list) -> str:
    # both runs import the module the swap patches before the command's modules, so they differ by the swap alone
    return f"import sys\nimport {module}\n{swap}\nimport wgcad.cli\nsys.argv = ['wgcad', *{argv!r}]\nwgcad.cli.run()\n"


def _once(code: str) -> tuple[float, float]:
    """Wall and CPU seconds (user + system) of one whole process running ``code``."""
    t = time.perf_counter()
    p = subprocess.Popen(
        [sys.executable, "-c", code],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    code_ = os.waitstatus_to_exitcode(status)
    if code_ not in (0, 1):
        raise SystemExit(f"failed ({code_}): {p.stderr.read().decode()[-500:]}")
    p.stderr.close()
    return wall, usage.ru_utime + usage.ru_stime


def measure(module: str, swap: str, argv: list, n: int, tmp: Path) -> dict:
    """Medians of ``n`` pairs of runs, the command as shipped (A) and swapped (B), each writing its own folder."""
    shipped = _script(module, "", [str(a).replace("{out}", str(tmp / "a")) for a in argv])
    swapped = _script(module, swap, [str(a).replace("{out}", str(tmp / "b")) for a in argv])
    a, b = [], []
    _once(shipped), _once(swapped)  # warm the file cache
    for _ in range(n):
        a.append(_once(shipped))
        b.append(_once(swapped))
    med = lambda runs, i: statistics.median(r[i] for r in runs)  # noqa: E731
    return {"a_cpu": med(a, 1), "b_cpu": med(b, 1), "a_wall": med(a, 0), "b_wall": med(b, 0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-n", type=int, default=7, help="pairs of runs per command (default 7)")
    ap.add_argument("--only", choices=sorted(COPIES), action="append", help="only these copies")
    args = ap.parse_args()
    rows = [
        "| copy | instead of | command | A cpu s | B cpu s | share (B - A) / B | A wall s | B wall s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for name, (instead, module, swap, commands) in COPIES.items():
            if args.only and name not in args.only:
                continue
            for label, argv in commands:
                r = measure(module, swap, argv, args.n, Path(tmp))
                share = (r["b_cpu"] - r["a_cpu"]) / r["b_cpu"]
                rows.append(
                    f"| {name} | {instead} | {label} | {r['a_cpu']:.3f} | {r['b_cpu']:.3f} | {share:.0%} | "
                    f"{r['a_wall']:.3f} | {r['b_wall']:.3f} |"
                )
                print(rows[-1], flush=True)
    load = os.getloadavg()[0]
    text = "\n".join(rows) + f"\n\nmedians of {args.n} pairs, load average {load:.1f}\n"
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "copies.md").write_text(text)
    print(f"\nmedians of {args.n} pairs, load average {load:.1f}; written to {OUT / 'copies.md'}")


if __name__ == "__main__":
    main()
