"""benchmarks/mutation.py's merge of a run of survivors into the set's last run: each mutant counted once, and the
mutants a run's budget did not reach run then too (a run cut short can be finished without running the set again)."""

import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location("mutation", Path(__file__).parents[1] / "benchmarks" / "mutation.py")
mutation = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mutation)


def _s(name, status="survived"):
    return {"mutant": name, "status": status, "diff": []}


def test_a_rerun_counts_each_survivor_and_each_unchecked_mutant_once():
    prev = {
        "set": "x",
        "mutants": 10,
        "counts": {"killed": 5, "survived": 2, "not checked": 3},
        "survivors": [_s("a"), _s("b")],
        "unchecked": ["c", "d", "e"],
    }
    status = {"a": "killed", "b": "survived", "c": "killed", "d": "survived", "e": "not checked"}
    rerun = {"status": status, "survivors": [_s("b"), _s("d")], "tests": ["t"], "seconds": 1.0}
    r = mutation._merge(prev, rerun)
    assert r["counts"] == {"killed": 7, "survived": 2, "not checked": 1}
    assert r["score"] == 0.7 and r["unchecked"] == ["e"] and r["rerun_of"] == 5
    assert sorted(s["mutant"] for s in r["survivors"]) == ["b", "d"]


def test_a_run_before_the_unchecked_list_merges_as_before():
    prev = {"set": "x", "mutants": 4, "counts": {"killed": 2, "survived": 2}, "survivors": [_s("a"), _s("b")]}
    rerun = {"status": {"a": "killed", "b": "not checked"}, "survivors": [], "tests": ["t"], "seconds": 1.0}
    r = mutation._merge(prev, rerun)
    assert r["counts"] == {"killed": 3, "survived": 1} and r["unchecked"] == []
    assert [s["mutant"] for s in r["survivors"]] == ["b"]
