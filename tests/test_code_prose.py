"""Rules of the code's own text (docs/architecture.md): no module imports another's private name (a name shared
between modules is public, in one place), and no tracker numbers in the code (the tracker is not in the
repository: the code says why in words), no run times in its prose (they go stale)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "wgcad"
MODULES = sorted(PACKAGE.rglob("*.py"))


def _private_imports(path: Path) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module != "__future__":
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__"):
                    out.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}: imports {a.name}")
    return out


def test_no_module_imports_a_private_name_of_another():
    found = [x for p in MODULES for x in _private_imports(p)]
    assert not found, "\n".join(found)


def test_the_check_finds_a_private_import(tmp_path):
    """The scan itself fails on a planted case (an alias to a private name is still one)."""
    p = tmp_path / "wgcad" / "m.py"
    p.parent.mkdir()
    p.write_text("from .other import _hidden as shown\n")
    global PACKAGE
    saved, PACKAGE = PACKAGE, tmp_path / "wgcad"
    try:
        assert _private_imports(p) == ["wgcad/m.py:1: imports _hidden"]
    finally:
        PACKAGE = saved


TRACKER = re.compile(r"\bissues? #?\d+|\btask #?\d+", re.IGNORECASE)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_tracker_numbers_in_the_code(path):
    hits = [
        f"{i}: {line.strip()}"
        for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if TRACKER.search(line)
    ]
    assert not hits, "\n".join(hits)


#: a run time quoted in the code's prose goes stale with the next machine or release: milliseconds, seconds of CPU,
#: wall or whole-process time, a before -> after timing (benchmarks/ and the README carry the measured figures)
TIMING = re.compile(
    r"\b\d+(\.\d+)?(-\d+(\.\d+)?)? ?ms\b|\b\d+(\.\d+)?(-\d+(\.\d+)?)? s (CPU|wall|whole)|\d s -> |-> \d+(\.\d+)? s\b"
)


def test_no_run_times_in_the_code():
    hits = [
        f"{p.relative_to(PACKAGE.parent)}:{i}: {line.strip()}"
        for p in MODULES
        for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if TIMING.search(line)
    ]
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize(
    "line", ["# 3.2 ms per factorisation", "(1.2-1.3 s whole process)", "d2 2.49 -> 2.0 s)", "~30ms of import"]
)
def test_the_timing_check_finds_a_planted_one(line):
    assert TIMING.search(line)
