"""Issue 43, flags: one bound and one message per flag, no silently ignored flag, negative torques refused with
the reason, the same --workers rule in sweep and design, output folders judged before any work."""

import argparse

import pytest
from conftest import TEMPLATES

import wgcad.cli.generate
import wgcad.cli.ke
import wgcad.cli.parts
import wgcad.cli.sector
from wgcad.audit import FLAGS, RunSettings
from wgcad.cli import COMMANDS, build_parser, main
from wgcad.cli.bounds import COMMAND_BOUNDS, FLAG_BOUNDS, bound_of
from wgcad.errors import DesignError

D1 = str(TEMPLATES / "d1_involute.toml")


def _err(capsys, argv) -> tuple[int, str]:
    try:
        code = main(argv)
    except SystemExit as e:  # argparse's refusals exit while parsing
        code = e.code
    return code, capsys.readouterr().err


def _rule(line: str) -> str:
    """The rule of a refusal, without the value it quotes and the 'argument ' argparse puts before the flag."""
    return line.split(", got")[0].replace("argument ", "")


@pytest.mark.parametrize("value", ["0.00001", "0", "100"])
def test_step_deg_has_one_rule_whether_the_parser_or_the_audit_judges_it(capsys, value):
    # main had "(0, 90] deg" from the parser and "[1e-4, 90] degrees" from RunSettings for 0 < step < 1e-4
    code, err = _err(capsys, ["audit", D1, "--step-deg", value])
    assert code == 2 and err.count("\n") == 1
    with pytest.raises(DesignError) as lib:
        RunSettings(step_deg=1e-5).check(FLAGS)
    assert _rule(err.strip()) == "wgcad: error: " + _rule(str(lib.value))


def _commands_with(flag):
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return [(name, sp) for name, sp in sub.choices.items() if flag in sp._option_string_actions]


@pytest.mark.parametrize("flag", sorted(FLAG_BOUNDS) + sorted({f for _, f in COMMAND_BOUNDS}))
def test_every_bounded_flag_states_one_rule_below_and_above(capsys, flag):
    found = _commands_with(flag)
    assert found, flag
    for name, sp in found:
        if flag not in FLAG_BOUNDS and (name, flag) not in COMMAND_BOUNDS:
            continue  # e.g. audit --torque-nm: a list of levels (wgcad.numbers.read_values), not one number
        b = bound_of(name, flag)
        npos = sum(1 for a in sp._actions if not a.option_strings and a.dest != "help")
        msgs = set()
        for v in (b.lo - 1, b.hi * 10 + 1):
            with pytest.raises(SystemExit):
                sp.parse_args(["x"] * npos + [flag, f"{int(v)}" if b.whole else f"{v:g}"])
            msgs.add(_rule(capsys.readouterr().err.strip()))
        assert len(msgs) == 1 and b.rule() in msgs.pop(), (name, flag)


@pytest.mark.parametrize("argv", [["audit", D1, "--torque-nm", "-3000:0:500"], ["ke", D1, "--torque-nm", "-500"]])
def test_a_negative_torque_is_refused_in_one_line_saying_why(capsys, argv):
    code, err = _err(capsys, argv)
    assert code == 2 and err.count("\n") == 1
    assert "--torque-nm" in err and ">= 0 N m" in err and "working flanks" in err and "unrecognized" not in err


def test_sector_negative_torque_says_why(capsys):
    code, err = _err(capsys, ["sector", str(TEMPLATES / "d4_sectored.toml"), "--torque-nm", "-300"])
    assert code == 2 and err.count("\n") == 1 and "--torque-nm" in err and "working flanks" in err


def test_negative_values_reach_the_flags_that_take_them():
    ns = build_parser().parse_args(["audit", D1, "--cam-offset-deg", "-30", "--torque-nm", "0:3000:500"])
    assert ns.cam_offset_deg == -30.0
    ns = build_parser().parse_args(["generate", D1, "--generator-angle", "-30:0:15"])
    assert ns.generator_angle == [-30.0, -15.0, 0.0]


@pytest.mark.parametrize("flag,value", [("--omega-h", "10"), ("--eccentricity", "0.5")])
def test_kinematics_velocity_flags_are_refused_for_an_internal_generator(capsys, flag, value):
    code, err = _err(capsys, ["kinematics", D1, flag, value])  # main printed the ratios and said nothing
    assert code == 2 and err.count("\n") == 1 and flag in err and "deformation" in err


def test_kinematics_out_for_an_internal_generator_is_warned_about(capsys, tmp_path):
    code, err = _err(capsys, ["kinematics", D1, "--out", str(tmp_path / "k")])
    assert code == 0 and err.count("\n") == 1 and "warning: --out: nothing written" in err
    assert not (tmp_path / "k").exists()


def test_kinematics_omega_h_takes_effect_on_the_external_drive(tmp_path, capsys):
    d3 = str(TEMPLATES / "d3_external.toml")
    speeds = []
    for omega in ("1", "10"):
        assert main(["kinematics", d3, "--omega-h", omega, "--out", str(tmp_path / omega)]) == 0
        line = next(x for x in capsys.readouterr().out.splitlines() if "washer speed" in x)
        speeds.append(float(line.split("V_d = ")[1].split()[0]))
    assert speeds[1] == pytest.approx(10 * speeds[0], rel=1e-3)


def test_workers_0_means_in_this_process_in_design_as_in_sweep():
    req = str(TEMPLATES / "requirements" / "d1_ratio100.toml")
    assert build_parser().parse_args(["design", req, "--workers", "0"]).workers == 0  # refused on main
    assert build_parser().parse_args(["sweep", "s.toml", "--workers", "0"]).workers == 0
    from wgcad.synthesis.search import _client

    assert _client(0, None)[0] is None  # no Dask client: this process
    for name in ("design", "sweep"):
        sp = dict(_commands_with("--workers"))[name]
        assert "0: in this process, without Dask" in " ".join(sp.format_help().split())


def _boom(*a, **k):
    raise AssertionError("work started before the output folder was judged")


@pytest.mark.parametrize(
    "command,module,argv",
    [
        ("parts", wgcad.cli.parts, ["--out", "{bad}"]),
        ("generate", wgcad.cli.generate, ["--out", "{bad}"]),
        ("sector", wgcad.cli.sector, ["--out", "{bad}"]),
        ("ke", wgcad.cli.ke, ["--json", "{bad}/ke.json"]),
    ],
)
def test_an_unwritable_output_is_refused_before_any_work(tmp_path, monkeypatch, capsys, command, module, argv):
    """A folder under a regular file cannot be made (root ignores chmod, so not a read-only folder): the refusal
    must come before the design is even read (on main parts built the whole drive first, 3.9 s)."""
    blocker = tmp_path / "file"
    blocker.write_text("x")
    monkeypatch.setattr(module, "load_design", _boom)
    design = str(TEMPLATES / ("d4_sectored.toml" if command == "sector" else "d1_involute.toml"))
    code, err = _err(capsys, [command, design, *(a.format(bad=blocker / "o") for a in argv)])
    assert code == 2 and err.count("\n") == 1 and "AssertionError" not in err and "not writable" in err


def _codes(text: str) -> dict:
    """Exit code -> its line (continuations joined) in a help's "exit codes:" list."""
    out, code = {}, None
    for line in text.split("exit codes:")[1].splitlines():
        m = line[:7].strip()
        if m.isdigit():
            code = int(m)
            out[code] = line[7:]
        elif code is not None and line.startswith("       "):
            out[code] += " " + line.strip()
    return out


def test_the_top_level_help_lists_every_commands_exit_codes():
    # main's list of exit 1 named audit and sector only; rating and design return 1 too
    top = _codes(build_parser().format_help())
    for name, sp in _commands_with("--help"):
        for code, line in _codes(sp.format_help()).items():
            assert code in top, (name, code)
            if code in (1, 4):  # a command's own meaning of the code: the top-level line names the command
                assert name in top[code], (name, code, top[code])


@pytest.mark.parametrize("command", COMMANDS)
def test_a_command_parsed_alone_is_parsed_as_in_the_whole_parser(command):
    """main() registers only the command on its line (wgcad.cli.build_parser): that command's help, and the
    top-level help listing every command, are the whole parser's, word for word."""

    def sub_help(p):
        sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
        return sub.choices[command].format_help()

    whole, alone = build_parser(), build_parser(command)
    assert sub_help(alone) == sub_help(whole)
    assert alone.format_help() == whole.format_help()
