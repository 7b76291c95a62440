"""Memory estimate (wgcad.design.budget) against the measured peak of real runs.

Run from the repository root (not part of the test run, ~1 min):

    .venv/bin/python benchmarks/memory.py

Each run is a fresh ``wgcad`` process; its peak resident memory is read from
``/proc/self/status`` (VmHWM) at exit. Prints one Markdown table: the run,
the estimate the budget check makes (with the built gears' own vertex
counts), the measured peak and their ratio. Configurations stay below 1 GB.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from wgcad.design import load_design  # noqa: E402
from wgcad.design.budget import RunShape, estimate_run  # noqa: E402
from wgcad.drive import build_drive  # noqa: E402

CHILD = """
import json, sys
from wgcad.cli import main
code = main(sys.argv[1:])
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM:")][0].split()[1]
print(json.dumps({"code": code, "rss_mb": int(hwm) / 1024}))
"""

RUNS = [
    # (label, argv after the design, design, the run's shape, chord tol mm)
    ("generate D1", ["generate", "--quiet"], "d1_involute", RunShape(exports=True), 1e-3),
    (
        "generate D1 0.1 um",
        ["generate", "--quiet", "--chord-tol-um", "0.1"],
        "d1_involute",
        RunShape(exports=True),
        1e-4,
    ),
    (
        "generate D4 0.01 um",
        ["generate", "--quiet", "--chord-tol-um", "0.01"],
        "d4_discrete",
        RunShape(exports=True),
        1e-5,
    ),
    ("audit D1", ["audit", "--quiet"], "d1_involute", RunShape(angles=720, sections=3, exports=False), 1e-3),
    (
        "audit D1 step 0.05",
        ["audit", "--quiet", "--step-deg", "0.05"],
        "d1_involute",
        RunShape(angles=7200, sections=3, exports=False),
        1e-3,
    ),
    (
        "audit D1 step 0.01, 10 sections",
        ["audit", "--quiet", "--step-deg", "0.01", "--sections", "10"],
        "d1_involute",
        RunShape(angles=36000, sections=10, exports=False),
        1e-3,
    ),
    (
        "audit D4 no shortcuts step 0.25",
        ["audit", "--quiet", "--step-deg", "0.25", "--no-shortcuts"],
        "d4_discrete",
        RunShape(
            angles=1440, sections=3, exports=False, use_period=False, use_waves=False, use_mirror=False, bound=False
        ),
        1e-3,
    ),
]


def main() -> None:
    rows = []
    for label, argv, name, shape, tol in RUNS:
        design = ROOT / "templates" / f"{name}.toml"
        args = [argv[0], str(design), *argv[1:]]
        with tempfile.TemporaryDirectory() as tmp:
            if argv[0] == "generate":
                args += ["--out", tmp]
            p = subprocess.run([sys.executable, "-c", CHILD, *args], capture_output=True, text=True, cwd=ROOT)
        res = json.loads(p.stdout.strip().splitlines()[-1])
        d = load_design(design)
        drive = build_drive(d, tol=tol)
        counts = {"flexspline": len(drive.flex.period) - 1, "rigid": len(drive.rigid.period) - 1}
        est = estimate_run(d, tol, run=shape, vertices_per_tooth=counts).memory_mb
        rows.append((label, est, res["rss_mb"]))
        print(f"{label}: estimate {est:.0f} MB, measured peak {res['rss_mb']:.0f} MB", file=sys.stderr)
    print("| run | estimate, MB | measured peak, MB | estimate / peak |")
    print("|---|---|---|---|")
    for label, est, rss in rows:
        print(f"| {label} | {est:.0f} | {rss:.0f} | {est / rss:.2f} |")


if __name__ == "__main__":
    main()
