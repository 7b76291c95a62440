"""Flags that take lists of numbers (--torque-nm of audit and ke, --generator-angle of generate and parts) and step
flags: bounded before anything is built, infinity and NaN refused as bad input, negative numbers read as values.

Every refusal here is one line on stderr naming the flag and the rule, exit 2, no traceback."""

import os
import subprocess
import sys

import pytest
from conftest import ROOT, TEMPLATES

import wgcad.report.load
from wgcad.cli import build_parser, main
from wgcad.constants import MAX_GENERATOR_ANGLES, MAX_LOAD_LEVELS
from wgcad.errors import DesignError
from wgcad.numbers import read_values

D1 = str(TEMPLATES / "d1_involute.toml")
D2 = str(TEMPLATES / "d2_imperfect.toml")
D4 = str(TEMPLATES / "d4_sectored.toml")


def outcome(argv, capsys) -> tuple[int, str]:
    """Exit code and stderr of ``wgcad ARGV`` in this process (argparse's refusals exit through SystemExit)."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as e:
        code = e.code
    return code, capsys.readouterr().err


def refused(code, err, *words):
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("wgcad: error: ") and "Traceback" not in err, err
    for w in words:
        assert w in err, err


class _NoSolve(BaseException):
    """Not an Exception: main() would turn one into exit 3."""


@pytest.fixture
def no_solve(monkeypatch):
    """The load audit's solve replaced by a sentinel: a refusal must come before it, a run that passes the checks
    reaches it."""

    def load_run(*a, **k):
        raise _NoSolve

    monkeypatch.setattr(wgcad.report.load, "load_run", load_run)


# -- the one parser ---------------------------------------------------------------------------------------


def test_read_values_forms():
    kw = {"what": "torques", "unit": "N m", "max_count": 20, "lo": 0.0}
    assert read_values("--t", "0:3000:250", **kw) == [250.0 * i for i in range(13)]
    assert read_values("--t", "0:1000:300", **kw) == [0.0, 300.0, 600.0, 900.0]  # STOP off the grid: not included
    assert read_values("--t", " 5 ", **kw) == [5.0]
    assert read_values("--t", "0,500,1000", **kw) == [0.0, 500.0, 1000.0]
    assert read_values("--t", "0:20:1", **{**kw, "max_count": 21}) == [float(i) for i in range(21)]


@pytest.mark.parametrize(
    "text, words",
    [
        ("0:inf:1", ["finite", "inf"]),
        ("0:1:nan", ["finite", "nan"]),
        ("nan", ["finite"]),
        ("1,-inf", ["finite"]),
        ("0:1e12:1", ["1000000000001 torques", "more than the 20"]),
        ("0:1e308:1e-300", ["more than the 20"]),  # (STOP - START) / STEP overflows a float
        ("-1e308:1e308:1", ["more than the 20"]),  # STOP - START overflows a float
        ("0:20:1", ["21 torques"]),
        (",".join(["1"] * 21), ["21 torques"]),
        ("0:1:0", ["STEP > 0"]),
        ("0:1:-1", ["STEP > 0"]),
        ("5:1:1", ["STOP >= START"]),
        ("1:2", ["expected START:STOP:STEP"]),
        ("1:2:3:4", ["expected START:STOP:STEP"]),
        ("1,,2", ["expected START:STOP:STEP"]),
        ("", ["expected START:STOP:STEP"]),
        ("-5", [">= 0 N m", "-5"]),
        ("-10:0:5", [">= 0 N m", "-10"]),
    ],
)
def test_read_values_refusals_name_the_flag(text, words):
    with pytest.raises(DesignError) as e:
        read_values("--t", text, what="torques", unit="N m", max_count=20, lo=0.0)
    assert e.value.field == "--t" and "\n" not in str(e.value)
    for w in words:
        assert w in e.value.rule, e.value.rule


def test_a_huge_range_is_refused_without_building_it():
    """``0:1e12:1`` grew a list to 21 GB before any check: run under a 1 GB address-space cap, the refusal must come
    before any list is built (a MemoryError would be exit 3)."""
    code = (
        "import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30)); "
        "from wgcad.cli import main; sys.exit(main(sys.argv[1:]))"
    )
    for cmd in (["audit", D1, "--torque-nm", "0:1e12:1"], ["ke", D2, "--torque-nm", "1:1e12:1"]):
        r = subprocess.run(
            [sys.executable, "-c", code, *cmd],
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=300,
        )
        refused(r.returncode, r.stderr, "--torque-nm", "more than the 1000")


# -- torque levels: audit --torque-nm, ke --torque-nm --------------------------------------------------------


@pytest.mark.parametrize("cmd", [["audit", D1], ["ke", D2]])
@pytest.mark.parametrize(
    "spec, words",
    [
        ("0:inf:1", ["finite"]),
        ("inf", ["finite"]),
        ("0:3000:0.001", ["3000001 torques", f"more than the {MAX_LOAD_LEVELS}"]),
        (f"0:{MAX_LOAD_LEVELS}:1", [f"{MAX_LOAD_LEVELS + 1} torques"]),
    ],
)
def test_torque_ranges_are_bounded_before_the_design_is_read(cmd, spec, words, capsys, tmp_path):
    missing = str(tmp_path / "missing.toml")  # the flag is judged first: the design is never opened
    for design in (cmd[1], missing):
        code, err = outcome([cmd[0], design, "--torque-nm", spec], capsys)
        refused(code, err, "--torque-nm", *words)


def test_negative_torques_reach_the_rule_not_argparse(capsys):
    """argparse took ``-3000:0:500`` for an unknown option ("unrecognized arguments"): now the value is read, in the
    spaced form as with ``=``, and judged by the rule."""
    for argv in (["--torque-nm", "-3000:0:500"], ["--torque-nm=-3000:0:500"], ["--torque-nm", "-5"]):
        code, err = outcome(["audit", D1, *argv], capsys)
        refused(code, err, "--torque-nm", ">= 0 N m")
        assert "unrecognized" not in err
    code, err = outcome(["ke", D2, "--torque-nm", "-80,800"], capsys)
    refused(code, err, "--torque-nm", ">= 0 N m")


def test_negative_numbers_are_values_of_every_flag():
    p = build_parser()
    for spaced, joined in (
        (["generate", D1, "--generator-angle", "-30,-15"], ["generate", D1, "--generator-angle=-30,-15"]),
        (["parts", D1, "--generator-angle", "-45:45:45"], ["parts", D1, "--generator-angle=-45:45:45"]),
        (
            ["audit", D1, "--torque-nm", "0", "--cam-offset-deg", "-1e-3"],
            ["audit", D1, "--torque-nm=0", "--cam-offset-deg=-1e-3"],
        ),
    ):
        assert vars(p.parse_args(spaced)) == vars(p.parse_args(joined))
    assert p.parse_args(["generate", D1, "--generator-angle", "-30,-15"]).generator_angle == [-30.0, -15.0]
    assert p.parse_args(["parts", D1, "--generator-angle", "-45:45:45"]).generator_angle == [-45.0, 0.0, 45.0]
    assert p.parse_args(["audit", D1, "--torque-nm", "0", "--cam-offset-deg", "-1e-3"]).cam_offset_deg == -1e-3
    # an option is still an option: --torque-nm alone before another flag is the rated sweep
    assert p.parse_args(["audit", D1, "--torque-nm", "--quiet"]).torque_nm == "rated"


def test_the_level_count_meets_the_memory_budget(capsys, no_solve):
    """751 levels at 6 sections: ~2.3 GB of solved states by the estimate, over the default 2 GB budget: refused
    naming the flags before the first solve; a raised budget lets the same run through to the solve."""
    args = ["audit", D1, "--torque-nm", "0:3000:4", "--sections", "6"]
    code, err = outcome(args, capsys)
    refused(code, err, "--torque-nm", "751 torque levels", "MB", "--max-memory-mb")
    with pytest.raises(_NoSolve):
        main([*args, "--max-memory-mb", "4000"])
    with pytest.raises(_NoSolve):  # the same levels at 3 sections fit the default budget
        main(["audit", D1, "--torque-nm", "0:3000:4"])
    code, err = outcome(["audit", D1, "--torque-nm", "0:3000:4", "--compare", D1], capsys)
    refused(code, err, "--torque-nm", "x 2 sweeps")  # --compare holds the audit's states while it sweeps again


def test_ke_torques_must_be_positive(capsys):
    code, err = outcome(["ke", D2, "--torque-nm", "0,80"], capsys)
    refused(code, err, "--torque-nm", "> 0 N m")


# -- generator angles: generate and parts --generator-angle -----------------------------------------------------


@pytest.mark.parametrize("cmd", ["generate", "parts"])
def test_generator_angles_are_bounded(cmd, capsys, tmp_path):
    out = tmp_path / "out"
    many = ",".join(str(i) for i in range(MAX_GENERATOR_ANGLES + 1))
    for spec, words in (
        ("0:360:0.5", ["721 angles", f"more than the {MAX_GENERATOR_ANGLES}"]),
        (many, [f"{MAX_GENERATOR_ANGLES + 1} angles"]),
        ("inf", ["finite"]),
        ("0,nan", ["finite"]),
        ("3601", ["[-3600, 3600] deg"]),
        ("0,x", ["expected START:STOP:STEP"]),
    ):
        code, err = outcome([cmd, D1, "--out", out, "--generator-angle", spec], capsys)
        refused(code, err, "--generator-angle", *words)
    assert not out.exists()
    p = build_parser()
    assert p.parse_args([cmd, D1, "--generator-angle", "0:350:10"]).generator_angle == [10.0 * i for i in range(36)]
    assert p.parse_args([cmd, D1, "--generator-angle", "-0,0,15,15"]).generator_angle == [0.0, 15.0]


# -- step flags ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("step", ["5e-324", "1e-300", "1e-9"])
def test_a_sector_step_too_fine_is_a_budget_refusal(step, capsys, tmp_path):
    """5e-324 deg made 180 / step infinite: an OverflowError (exit 3) in the estimate; now the budget's refusal."""
    code, err = outcome(["sector", D4, "--step-deg", step, "--out", tmp_path / "o"], capsys)
    refused(code, err, "--step-deg", "MB", "--max-memory-mb")
    assert "inf" not in err


@pytest.mark.parametrize("step", ["5e-324", "inf", "nan", "-1"])
def test_audit_steps_are_bounded(step, capsys):
    code, err = outcome(["audit", D1, "--step-deg", step, "--quiet"], capsys)
    refused(code, err, "--step-deg")


def test_audit_angles_meet_the_memory_budget(capsys):
    code, err = outcome(["audit", D1, "--angles", "3600000", "--quiet"], capsys)
    refused(code, err, "--max-memory-mb", "audit samples")
