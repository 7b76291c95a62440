"""Fuzzing the design input (issue 13): mutated templates give a clean result or a one-line WgcadError naming a real field, never another exception, nothing written on refusal.

The bundled templates are mutated in their numbers (huge, tiny, negative,
non-finite, off by one), types (strings, booleans, arrays, nested arrays,
inline tables) and structure (keys and tables removed, added, renamed,
replaced). Every mutant is loaded and built in-process; every few are also
run through ``wgcad generate`` and ``wgcad audit`` in-process with coarse
settings. Seeded (``derandomize``) and bounded: the default suite runs
``WGCAD_FUZZ_EXAMPLES`` (default 120) mutants in a few seconds; set it to
thousands for a soak.
"""

import math
import os
import tomllib
from dataclasses import fields
from pathlib import Path

import pytest
from conftest import TEMPLATES
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from wgcad.cli import main
from wgcad.design import TABLES, load_design
from wgcad.drive import build_drive
from wgcad.errors import DesignError, InputFileError, WgcadError
from wgcad.testing import to_toml

N_EXAMPLES = int(os.environ.get("WGCAD_FUZZ_EXAMPLES", "120"))
NAMES = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"]
TEMPLATE_DATA = {n: tomllib.loads((TEMPLATES / f"{n}.toml").read_text()) for n in NAMES}
#: run settings of the fuzz: coarse outlines and a small budget keep each run short
BUDGET_MB = 400.0
CHORD_TOL_UM = 10.0
#: names a refusal may carry besides design fields: run settings and flags
FLAGS = {"--max-memory-mb", "chord_tol", "--step-deg", "--sections", "--chord-tol-um", "--interference-tol-um"}
REAL_FIELDS = {f"{t}.{f.name}" for t, cls in TABLES.items() for f in fields(cls)} | set(TABLES)


def test_the_writer_round_trips_the_templates():
    for name, data in TEMPLATE_DATA.items():
        assert tomllib.loads(to_toml(data)) == data, name


# ----------------------------------------------------------------------------- mutations
_numbers = st.one_of(
    st.sampled_from([0, -1, 1, 2, 7, 8, 9, 3000, 3001, 10**5, 10**6, 10**9, 10**12, 10**39, -(10**39), 2**63 - 1]),
    st.sampled_from(
        [0.0, -0.0, 1e-300, -1e-9, 1e-6, 0.5, 1e5, 1e6, 1e9, 1e12, 1e39, 1e308, -1e308, math.inf, -math.inf, math.nan]
    ),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**40), 10**40),
)
_others = st.one_of(
    st.text(max_size=30),
    st.booleans(),
    st.lists(st.integers(), max_size=3),
    st.integers(1, 60).map(lambda n: [1] if n == 1 else [[1]] * 2),
    st.just({"a": 1}),
    st.just(["x", 1.5]),
)


@st.composite
def mutants(draw):
    name = draw(st.sampled_from(NAMES))
    data = {k: dict(v) if isinstance(v, dict) else v for k, v in TEMPLATE_DATA[name].items()}
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(
            st.sampled_from(
                [
                    "scale",
                    "number",
                    "other",
                    "drop_key",
                    "add_key",
                    "drop_table",
                    "add_table",
                    "table_value",
                    "schema_key",
                ]
            )
        )
        tables = [t for t in data if isinstance(data[t], dict)]
        if not tables:
            break
        t = draw(st.sampled_from(tables))
        keys = list(data[t])
        k = draw(st.sampled_from(keys)) if keys else None
        if (
            kind == "scale"
            and k is not None
            and isinstance(data[t][k], (int, float))
            and not isinstance(data[t][k], bool)
        ):
            f = draw(st.sampled_from([1e3, 1e6, 1e-3, -1.0, 10.0, 0.1, 1.5]))
            v = data[t][k] * f
            data[t][k] = int(v) if isinstance(data[t][k], int) and abs(v) < 1e300 else v
        elif kind == "number" and k is not None:
            data[t][k] = draw(_numbers)
        elif kind == "other" and k is not None:
            data[t][k] = draw(_others)
        elif kind == "drop_key" and k is not None:
            del data[t][k]
        elif kind == "add_key":
            data[t][draw(st.sampled_from(["modul", "z", "beta", "extra", "w0"]))] = draw(_numbers)
        elif kind == "drop_table":
            del data[t]
        elif kind == "add_table":
            data[draw(st.sampled_from(["drives", "gear", "extra"]))] = {"x": 1}
        elif kind == "table_value":
            data[t] = draw(st.one_of(_numbers, _others))
        elif kind == "schema_key":  # a key the template leaves at its default
            cls = TABLES.get(t)
            if cls is not None:
                data[t][draw(st.sampled_from([f.name for f in fields(cls)]))] = draw(st.one_of(_numbers, _others))
    return name, data


# ----------------------------------------------------------------------------- the oracle
def check_refusal(e: WgcadError) -> None:
    msg = str(e)
    assert "\n" not in msg and msg, repr(msg)
    if isinstance(e, DesignError):
        real = e.field in REAL_FIELDS or e.field in FLAGS
        unknown = "unknown" in e.rule  # a misspelt key or table is named as the user wrote it
        assert real or unknown, f"names no real field: {msg!r}"
        table = e.field.split(".")[0]
        if unknown and "." in e.field:
            assert table in TABLES, msg
    else:
        assert isinstance(e, InputFileError), type(e)


def files_under(path: Path) -> list:
    return [p for p in path.rglob("*") if not p.is_dir()] if path.exists() else []


STATS = {"ok": 0, "refused": 0, "cli": 0}


def _one(tmp_root: Path, case, run_cli: bool):
    name, data = case
    idx = STATS["ok"] + STATS["refused"]
    path = tmp_root / f"m{idx}.toml"
    path.write_text(to_toml(data))
    try:
        drive = build_drive(load_design(path), tol=CHORD_TOL_UM * 1e-3, max_memory_mb=BUDGET_MB)
        STATS["ok"] += 1
        assert drive.flex.outline.size and drive.rigid.outline.size
    except WgcadError as e:
        check_refusal(e)
        STATS["refused"] += 1
    if not run_cli:
        return
    STATS["cli"] += 1
    out = tmp_root / f"out{idx}"
    common = ["--max-memory-mb", str(BUDGET_MB), "--chord-tol-um", str(CHORD_TOL_UM)]
    for argv in (
        ["generate", str(path), "--out", str(out / "g"), "--no-stl", "--quiet", *common],
        [
            "audit",
            str(path),
            "--step-deg",
            "10",
            "--sections",
            "2",
            "--quiet",
            "--json",
            str(out / "a" / "audit.json"),
            *common,
        ],
    ):
        code = main(argv)  # anything but a WgcadError escapes here and fails the test
        assert code in (0, 1, 2), (argv, code)
        sub = out / ("g" if argv[0] == "generate" else "a")
        if code == 2:
            assert files_under(sub) == [], f"files written on refusal: {files_under(sub)}"
        elif argv[0] == "generate":
            assert len(list(sub.glob("*.report.json"))) == 1  # one report per design
        else:
            assert (sub / "audit.json").exists()


def test_mutated_templates_build_or_refuse_in_one_line(tmp_path, capsys):
    for key in STATS:
        STATS[key] = 0
    counter = {"n": 0}

    @settings(
        derandomize=True,
        max_examples=N_EXAMPLES,
        deadline=None,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
    )
    @given(mutants())
    def sweep(case):
        counter["n"] += 1
        _one(tmp_path, case, run_cli=counter["n"] % 12 == 0)

    sweep()
    err = capsys.readouterr().err
    # every refusal on the command line is one line
    for line in err.splitlines():
        assert line.startswith("wgcad: error: "), line
    n = STATS["ok"] + STATS["refused"]
    print(f"\nfuzz: {n} mutants, {STATS['ok']} built, {STATS['refused']} refused, {STATS['cli']} run through the CLI")
    # not vacuous: both outcomes occur and the CLI was exercised
    assert STATS["ok"] >= 0.05 * n and STATS["refused"] >= 0.3 * n and STATS["cli"] >= N_EXAMPLES // 12 - 1


# ----------------------------------------------------------------------------- the cases issue 13 listed, pinned
@pytest.mark.parametrize(
    "table,key,value",
    [
        ("drive", "z_flex", 10**39),
        ("drive", "z_rigid", 10**39),
        ("drive", "module", 1e39),
        ("drive", "module", 1e12),
        ("drive", "z_flex", 10**5),
        ("drive", "z_rigid", 10**9),
        ("drive", "module", 1e9),
        ("drive", "module", 1e6),
        ("drive", "z_rigid", 10**6),
    ],
)
def test_issue_13_cases_are_one_line_refusals(table, key, value, tmp_path, capsys):
    data = {k: dict(v) for k, v in TEMPLATE_DATA["d1_involute"].items()}
    data[table][key] = value
    path = tmp_path / "d.toml"
    path.write_text(to_toml(data))
    for argv in (["generate", str(path), "--out", str(tmp_path / "o")], ["audit", str(path)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("wgcad: error: drive.")
    assert files_under(tmp_path / "o") == []
