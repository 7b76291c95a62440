"""Benchmark of the clearance audit of an imperfect drive (wgcad.clearance.imperfect): time and peak memory over a full generator revolution, 3 sections.

Run from the repository root (not part of the test run, ~1 min):

    .venv/bin/python benchmarks/audit_imperfect.py

Cases: D1 with D2's [S4] tolerances (the [imperfections] table of
templates/d2_imperfect.toml: the two gears are the same size), and D2 itself
(templates/d2_imperfect.toml), at 0.5 and 0.25 deg. Times are in-process,
best of 3, against the perfect audit of the same design in the same run
(ratio); with and without the refinement on the exact curves (the
refinement is the same code as the perfect audit's). Peak memory: resident
peak (VmHWM) of a fresh ``wgcad audit`` process, and the audit's own peak
Python allocation (tracemalloc, numpy included). The machine and its load
are printed with the figures.
"""

from __future__ import annotations

import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from _timing import best_of  # noqa: E402

from wgcad.audit import RunSettings, run_audit  # noqa: E402

CHILD = """
import json, sys
from wgcad.cli import main
code = main(sys.argv[1:])
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM:")][0].split()[1]
print(json.dumps({"code": code, "rss_mb": int(hwm) / 1024}))
"""


def _designs(tmp: Path) -> dict:
    imp_table = (ROOT / "templates" / "d2_imperfect.toml").read_text().split("[imperfections]", 1)[1]
    d1 = (ROOT / "templates" / "d1_involute.toml").read_text()
    d2 = (ROOT / "templates" / "d2_imperfect.toml").read_text()
    out = {}
    for name, text in (("D1 + [S4] errors", d1 + "\n[imperfections]" + imp_table), ("D2 [S4]", d2)):
        stem = re.sub(r"\W+", "_", name).strip("_").lower()
        imperfect = tmp / f"{stem}.toml"
        imperfect.write_text(text)
        perfect = tmp / f"{stem}_perfect.toml"
        perfect.write_text(text.split("[imperfections]", 1)[0])
        out[name] = (imperfect, perfect)
    return out


def _rss(design: Path, step: float) -> float:
    p = subprocess.run(
        [sys.executable, "-c", CHILD, "audit", str(design), "--quiet", "--step-deg", str(step)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    return json.loads(p.stdout.strip().splitlines()[-1])["rss_mb"]


def _traced_peak(design: Path, rs: RunSettings) -> float:
    tracemalloc.start()
    run_audit(design, rs)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 1e6


def main() -> None:
    load = os.getloadavg()
    out = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "load_avg_1_5_15": [round(x, 2) for x in load],
        "rows": [],
    }
    print(json.dumps({k: out[k] for k in ("machine", "load_avg_1_5_15")}), file=sys.stderr)
    with tempfile.TemporaryDirectory() as tmp:
        for name, (imperfect, perfect) in _designs(Path(tmp)).items():
            for step in (0.5, 0.25):
                rs = RunSettings(step_deg=step, sections=3)
                rs_poly = RunSettings(step_deg=step, sections=3, refine=False)
                t_imp, (_, res) = best_of(lambda: run_audit(imperfect, rs))
                t_poly, (_, res_poly) = best_of(lambda: run_audit(imperfect, rs_poly))
                t_per, (_, res_per) = best_of(lambda: run_audit(perfect, rs))
                row = {
                    "case": name,
                    "step_deg": step,
                    "samples": res.counts["samples"],
                    "audit_s": round(res.elapsed_s, 3),
                    "audit_no_refine_s": round(res_poly.elapsed_s, 3),
                    "perfect_audit_s": round(res_per.elapsed_s, 3),
                    "ratio_to_perfect": round(res.elapsed_s / res_per.elapsed_s, 2),
                    "wall_s_incl_build": round(t_imp, 3),
                    "wall_no_refine_s_incl_build": round(t_poly, 3),
                    "min_clearance_um": round(1e3 * res.min_clearance, 4),
                    "perfect_min_clearance_um": round(1e3 * res_per.min_clearance, 4),
                    "evaluated": res.counts["evaluated"],
                    "perfect_grid_evaluated": res.counts["perfect_evaluated"],
                    "refined": res.counts["refined"],
                    "chunks": res.counts["chunks"],
                    "traced_peak_mb": round(_traced_peak(imperfect, rs), 1),
                    "process_peak_rss_mb": round(_rss(imperfect, step), 1),
                }
                out["rows"].append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)
    print(
        "| case | step, deg | samples | audit, s | without refinement, s | perfect audit, s | evaluated | peak RSS, MB | traced peak, MB |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in out["rows"]:
        print(
            f"| {r['case']} | {r['step_deg']} | {r['samples']} | {r['audit_s']} | {r['audit_no_refine_s']} | "
            f"{r['perfect_audit_s']} | {r['evaluated']} | {r['process_peak_rss_mb']} | {r['traced_peak_mb']} |"
        )
    dest = ROOT / "output" / "bench"
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "audit_imperfect.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
