"""Mutation testing of the core with mutmut: how many small wrong edits of a module its tests notice.

mutmut (``pip install mutmut``; not a dependency of wgcad or of its tests) makes one mutant per small edit of a
module (an operator flipped, a constant moved by one, a keyword dropped, an attribute's name changed) and runs the
tests that cover the module against each; a mutant no test fails on *survived*: a behaviour of the code no test
pins. Run from the repository root:

    .venv/bin/python benchmarks/mutation.py                       # every module set below (hours on 2 cores)
    .venv/bin/python benchmarks/mutation.py --only laws,ring      # some sets
    .venv/bin/python benchmarks/mutation.py --module wgcad/laws/harmonic.py --tests tests/test_laws.py

The checkout's working tree (uncommitted changes included) is copied to a temporary folder, mutmut runs there
(its ``mutants/`` folder stays out of the checkout) with the set's modules and only the set's tests, within
``--budget-min`` minutes a set, and the survivors are written with their diffs to
``output/mutation/<set>.md`` (a Markdown report) and the counts to ``output/mutation/summary.json``. Survivors
that change no behaviour (equivalent mutants) are listed in docs/mutation.md with the reason; the others are
killed by tests that check behaviour.

``--survivors`` runs only the last whole run's survivors of each set again (``output/mutation/<set>.json``), and
the mutants a run's budget did not reach (kept in that file as ``unchecked``), in a
fresh copy with the set's tests as they are now, and counts each mutant once: after tests are added against
survivors, minutes instead of the set's whole run. The modules must be unchanged (mutmut's mutant names are
numbered in their sources; a digest guards it) and the set's tests should only have grown.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "output" / "mutation"

#: the module sets: name -> (modules to mutate, the tests that cover them)
SETS = {
    "laws": (
        ["wgcad/laws/harmonic.py", "wgcad/laws/base.py", "wgcad/laws/coning.py"],
        ["tests/test_laws.py", "tests/test_coning.py", "tests/test_law_checks.py"],
    ),
    "ring": (
        ["wgcad/elastic/ring.py"],
        ["tests/test_elastic_ring.py", "tests/test_ring_checks.py", "tests/test_loaded_figures.py"],
    ),
    "solve": (["wgcad/elastic/solve.py"], ["tests/test_elastic_solver.py", "tests/test_solver_checks.py"]),
    "kinematics": (["wgcad/kinematics.py"], ["tests/test_kinematics.py", "tests/test_kinematics_checks.py"]),
    "plane": (["wgcad/plane.py", "wgcad/units.py"], ["tests/test_placement.py", "tests/test_kinematics.py"]),
    "placement": (
        ["wgcad/placement/law.py", "wgcad/placement/deformed.py"],
        ["tests/test_placement.py", "tests/test_placement_checks.py", "tests/test_deformed_checks.py"],
    ),
    # the fast checks only: a survivor runs every test that covers its function, and the whole of test_clearance,
    # test_refine and test_apart takes 75 s (one test 24 s): with them a whole run of the set took hours
    "clearance": (
        ["wgcad/clearance/distance.py", "wgcad/clearance/refine.py", "wgcad/clearance/apart.py"],
        [
            "tests/test_clearance_checks.py",
            "tests/test_refine.py::test_refined_pairs_match_dense_polygons[d1_involute-12]",
            "tests/test_refine.py::test_refined_pairs_match_dense_polygons[d4_discrete-12]",
            "tests/test_refine.py::test_exact_backlash_approached_from_apart_equals_newton_on_the_signed_figure[d1_involute]",
            "tests/test_refine.py::test_boundary_distance_matches_shapely",
            "tests/test_apart.py::test_batched_distance_equals_the_general_refinement",
            "tests/test_clearance.py::test_engine_equals_brute_force",
            "tests/test_clearance.py::test_pair_distance_on_two_threads_equals_shapely",
            "tests/test_clearance.py::test_deliberately_interfering_design_is_found_where_and_how_deep",
        ],
    ),
    "ke": (["wgcad/accuracy/ke.py", "wgcad/accuracy/ke_lanes.py"], ["tests/test_ke_checks.py"]),
    "profiles": (
        ["wgcad/profiles/involute.py", "wgcad/profiles/cycloid.py", "wgcad/profiles/pieces.py"],
        ["tests/test_profiles.py", "tests/test_pieces.py", "tests/test_piece_checks.py"],
    ),
}

#: what is copied into the temporary folder (the tests read templates, docs and the README)
COPY = ["wgcad", "tests", "templates", "docs", "examples", "freecad", "benchmarks", "README.md", "pyproject.toml"]


def _mutmut() -> list[str]:
    exe = Path(sys.executable).with_name("mutmut")
    if not exe.exists():
        sys.exit("benchmarks/mutation.py: mutmut is not installed here (pip install mutmut)")
    return [str(exe)]


def _config(modules, tests) -> str:
    q = lambda xs: "[" + ", ".join(json.dumps(x) for x in xs) + "]"  # noqa: E731
    return (
        "\n[tool.mutmut]\n"
        'source_paths = ["wgcad/"]\n'
        f"only_mutate = {q(modules)}\n"
        f"pytest_add_cli_args_test_selection = {q(tests)}\n"
        f"also_copy = {q([c for c in COPY if c != 'wgcad'])}\n"
    )


def _copy(dst: Path) -> None:
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache", "output", "_build", "mutants")
    for name in COPY:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, dst / name, ignore=ignore)
        elif src.exists():
            shutil.copy2(src, dst / name)


_LINE = re.compile(r"^\s*(\S+): (\w[\w ]*)$")


def _digest(modules) -> str:
    """A digest of the modules' sources: mutmut's mutant names hold only for the same sources."""
    h = hashlib.sha256()
    for m in modules:
        h.update(m.encode() + b"\0" + (ROOT / m).read_bytes())
    return h.hexdigest()[:16]


def _previous(name: str, modules) -> dict:
    """The last whole run of a set (``output/mutation/<set>.json``), to run its survivors again."""
    path = OUT / f"{name}.json"
    if not path.exists():
        sys.exit(
            f"benchmarks/mutation.py: --survivors: no earlier run of set '{name}' ({path}); run the whole set first"
        )
    prev = json.loads(path.read_text(encoding="utf-8"))
    if prev.get("digest") != _digest(modules):
        sys.exit(
            f"benchmarks/mutation.py: --survivors: the modules of set '{name}' changed since its run (the mutants' "
            "names no longer hold); run the whole set"
        )
    return prev


_SURVIVING = ("survived", "no tests", "timeout", "suspicious")

#: the survivors judged equivalent (the behaviour does not change), per set: ``{set: {"digest": .., "mutants":
#: {name: reason}}}``; read only while the set's modules are those the list was made on (the digest)
EQUIVALENT = ROOT / "benchmarks" / "mutation_equivalent.json"


def _equivalent(name: str, modules) -> dict:
    """The set's listed equivalent mutants (name -> reason), empty if none are listed for these sources."""
    if not EQUIVALENT.exists():
        return {}
    entry = json.loads(EQUIVALENT.read_text(encoding="utf-8")).get(name, {})
    return entry.get("mutants", {}) if entry.get("digest") == _digest(modules) else {}


def _with_equivalents(r: dict, equivalent: dict) -> dict:
    """The figures with the listed equivalents among the survivors set apart, and the score without them."""
    for s in r["survivors"]:
        if s["mutant"] in equivalent:
            s["equivalent"] = equivalent[s["mutant"]]
    n = sum("equivalent" in s for s in r["survivors"])
    killed = r["counts"].get("killed", 0)
    return r | {
        "equivalent": n,
        "score_without_equivalent": round(killed / (r["mutants"] - n), 4) if r["mutants"] > n else None,
    }


def _merge(prev: dict, rerun: dict) -> dict:
    """The earlier run's figures with its survivors' new statuses (each mutant counted once)."""
    counts = dict(prev["counts"])
    for s in prev["survivors"]:
        new = rerun["status"].get(s["mutant"], s["status"])
        if new == "not checked":  # not reached within the budget: as it was
            new = s["status"]
            rerun["survivors"].append(s)
        counts[s["status"]] -= 1
        counts[new] = counts.get(new, 0) + 1
    unchecked = []
    for m in prev.get("unchecked", []):
        new = rerun["status"].get(m, "not checked")
        if new == "not checked":
            unchecked.append(m)
            continue
        counts["not checked"] -= 1
        counts[new] = counts.get(new, 0) + 1
    counts = {k: v for k, v in counts.items() if v}
    killed = counts.get("killed", 0)
    kept = prev.pop("kept", [])
    return prev | {
        "counts": counts,
        "score": round(killed / prev["mutants"], 4) if prev["mutants"] else None,
        "tests": rerun["tests"],
        "survivors": rerun["survivors"] + kept,
        "rerun_seconds": rerun["seconds"],
        "rerun_of": len(prev["survivors"]) + len(prev.get("unchecked", [])),
        "unchecked": unchecked,
    }


def run_set(name: str, modules, tests, children: int, budget_min: float, names=()) -> dict:
    """Run mutmut on one set in a temporary copy (only the mutants ``names`` if given); the counts, the
    survivors' diffs and the run time."""
    mm = _mutmut()
    with tempfile.TemporaryDirectory(prefix=f"wgcad-mut-{name}-") as tmp:
        work = Path(tmp)
        _copy(work)
        with open(work / "pyproject.toml", "a", encoding="utf-8") as f:
            f.write(_config(modules, tests))
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONWARNINGS": "ignore"}
        t0 = time.perf_counter()
        timed_out = False
        try:
            subprocess.run(
                [*mm, "run", "--max-children", str(children), *names],
                cwd=work,
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                timeout=budget_min * 60.0,
            )
        except subprocess.TimeoutExpired:
            timed_out = True
        seconds = time.perf_counter() - t0
        res = subprocess.run([*mm, "results", "--all", "true"], cwd=work, env=env, capture_output=True, text=True)
        status = {}
        for line in res.stdout.splitlines():
            m = _LINE.match(line)
            if m:
                status[m.group(1)] = m.group(2)
        if names:  # the others read "not checked" in this copy
            status = {k: v for k, v in status.items() if k in set(names)}
        survivors = []
        for mutant, st in status.items():
            if st in _SURVIVING:
                diff = subprocess.run([*mm, "show", mutant], cwd=work, env=env, capture_output=True, text=True)
                lines = [x for x in diff.stdout.splitlines() if x[:1] in "-+" and x[:3] not in ("---", "+++")]
                survivors.append({"mutant": mutant, "status": st, "diff": lines})
    counts = {}
    for st in status.values():
        counts[st] = counts.get(st, 0) + 1
    total = len(status)
    killed = counts.get("killed", 0)
    return {
        "set": name,
        "modules": list(modules),
        "tests": list(tests),
        "mutants": total,
        "counts": counts,
        "score": round(killed / total, 4) if total else None,
        "seconds": round(seconds, 1),
        "budget_exhausted": timed_out,
        "digest": _digest(modules),
        "status": status,
        "survivors": survivors,
        # the mutants the budget did not reach: ``--survivors`` runs them too, so a run cut short can be finished
        "unchecked": sorted(k for k, v in status.items() if v == "not checked"),
    }


def _report(r: dict) -> str:
    lines = [
        f"# Mutation testing: {r['set']}",
        "",
        f"Modules: {', '.join(r['modules'])}; tests: {', '.join(r['tests'])}.",
        f"{r['mutants']} mutants, {r['counts']}; score {r['score']} (killed / all) in {r['seconds']} s"
        + (" (budget exhausted: not every mutant was run)" if r["budget_exhausted"] else "")
        + (
            f"; its {r['rerun_of']} survivors run again with these tests in {r['rerun_seconds']} s"
            if "rerun_of" in r
            else ""
        )
        + ".",
        "",
    ]
    if r.get("equivalent"):
        lines += [
            f"{r['equivalent']} of the survivors are listed as equivalent ({EQUIVALENT.name}, the reason under each); "
            f"the score without them is {r['score_without_equivalent']}.",
            "",
        ]
    for s in r["survivors"]:
        eq = f"; equivalent: {s['equivalent']}" if "equivalent" in s else ""
        lines += [f"## {s['mutant']} ({s['status']}{eq})", "", "```diff", *s["diff"], "```", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated set names: " + ", ".join(SETS))
    ap.add_argument("--module", action="append", help="a module to mutate (with --tests: one ad-hoc set)")
    ap.add_argument("--tests", action="append", help="a test file that covers --module")
    ap.add_argument("--max-children", type=int, default=2, help="mutants run at once (default 2, one per core)")
    ap.add_argument("--budget-min", type=float, default=60.0, help="minutes a set may take (default 60)")
    ap.add_argument(
        "--survivors",
        action="store_true",
        help="run only the last whole run's survivors of each set again (the modules unchanged; new tests welcome)",
    )
    args = ap.parse_args(argv)
    if args.module:
        if not args.tests:
            ap.error("--module needs --tests (the tests that cover it)")
        sets = {"adhoc": (args.module, args.tests)}
    else:
        names = args.only.split(",") if args.only else list(SETS)
        unknown = [n for n in names if n not in SETS]
        if unknown:
            ap.error(f"--only: unknown set(s) {', '.join(unknown)}; the sets: {', '.join(SETS)}")
        sets = {n: SETS[n] for n in names}
    OUT.mkdir(parents=True, exist_ok=True)
    summary_path = OUT / "summary.json"
    print(
        "| set | mutants | killed | survived | other | score | listed equivalent | score without them | s |\n"
        "|---|---|---|---|---|---|---|---|---|"
    )
    for name, (modules, tests) in sets.items():
        equivalent = _equivalent(name, modules)
        if args.survivors:
            prev = _previous(name, modules)
            # the listed equivalents are not run again: they survive whatever the tests
            prev = (
                prev
                | {"survivors": [s for s in prev["survivors"] if s["mutant"] not in equivalent]}
                | {"kept": [s for s in prev["survivors"] if s["mutant"] in equivalent]}
            )
            r = _merge(
                prev,
                run_set(
                    name,
                    modules,
                    tests,
                    args.max_children,
                    args.budget_min,
                    [s["mutant"] for s in prev["survivors"]] + list(prev.get("unchecked", [])),
                ),
            )
        else:
            r = run_set(name, modules, tests, args.max_children, args.budget_min)
        r = _with_equivalents(r, equivalent)
        (OUT / f"{name}.md").write_text(_report(r), encoding="utf-8")
        (OUT / f"{name}.json").write_text(
            json.dumps({k: v for k, v in r.items() if k != "status"}, indent=1), encoding="utf-8"
        )
        # read again before each write: another run of this script (another set) may have written meanwhile
        summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
        summary[name] = {k: v for k, v in r.items() if k not in ("survivors", "status")} | {
            "survived": len(r["survivors"])
        }
        summary_path.write_text(json.dumps(summary, indent=1), encoding="utf-8")
        c = r["counts"]
        other = r["mutants"] - c.get("killed", 0) - c.get("survived", 0)
        print(
            f"| {name} | {r['mutants']} | {c.get('killed', 0)} | {c.get('survived', 0)} | {other} | {r['score']} | "
            f"{r['equivalent']} | {r['score_without_equivalent']} | {r['seconds']} |"
        )
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
