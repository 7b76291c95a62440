"""What the CLI writes, and what it refuses to touch (issue 13): special files, stdout, reports per design,
re-runs, interrupted runs, internal errors, bad input of every subcommand, imports per command."""

import json
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.cli import build_parser, main

ROOT = TEMPLATES.parent
D4 = TEMPLATES / "d4_discrete.toml"


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def wgcad(*argv, cwd=None, env=None, **kw):
    """The installed entry point as a user runs it, in its own process."""
    e = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    return subprocess.run(
        [sys.executable, "-m", "wgcad", *map(str, argv)], cwd=cwd, env=e, capture_output=True, text=True, **kw
    )


def snapshot(folder: Path):
    """Every entry below ``folder`` with its type, size and modification time."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = os.lstat(p)
            out[str(p.relative_to(folder))] = (stat.S_IFMT(st.st_mode), st.st_size, st.st_mtime_ns)
    return out


def one_line_error(code, err, *words):
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("wgcad: error: "), err
    assert "Traceback" not in err
    for w in words:
        assert w in err, err


# -- output files that are not regular files are never replaced ---------------------------------


def special_files(tmp_path):
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    (tmp_path / "real.json").write_text("keep")
    link = tmp_path / "link.json"
    link.symlink_to(tmp_path / "real.json")
    folder = tmp_path / "folder.json"
    folder.mkdir()
    return {
        "/dev/null": Path("/dev/null"),
        "/dev/full": Path("/dev/full"),
        "/dev/stdout": Path("/dev/stdout"),
        "fifo": fifo,
        "symlink": link,
        "folder": folder,
    }


KINDS = ["/dev/null", "/dev/full", "/dev/stdout", "fifo", "symlink", "folder"]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("flag", ["--json", "--write-baseline"])
def test_audit_never_replaces_a_special_file(tmp_path, capsys, kind, flag):
    target = special_files(tmp_path)[kind]
    if not os.path.lexists(target):
        pytest.skip(f"{target} missing here")
    before = os.lstat(target)
    code, out, err = run(["audit", D4, flag, target], capsys)
    one_line_error(code, err, flag, "only new or regular files", f"{flag} - to write to standard output")
    after = os.lstat(target)
    assert (after.st_mode, after.st_ino, after.st_rdev) == (before.st_mode, before.st_ino, before.st_rdev)
    assert (tmp_path / "real.json").read_text() == "keep"
    assert out == ""  # refused before the audit ran


def test_plot_never_replaces_a_special_file(tmp_path, capsys):
    os.mkfifo(tmp_path / "p_vs_angle.png")
    code, out, err = run(["audit", D4, "--plot", tmp_path / "p"], capsys)
    one_line_error(code, err, "--plot", "p_vs_angle.png", "named pipe")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "p_vs_angle.png").st_mode)
    assert sorted(os.listdir(tmp_path)) == ["p_vs_angle.png"]


@pytest.mark.parametrize("kind", ["fifo", "symlink", "folder"])
def test_generate_never_replaces_a_special_file(tmp_path, capsys, kind):
    out = tmp_path / "out"
    out.mkdir()
    real = tmp_path / "real.stl"
    real.write_text("keep")
    target = out / "d4_discrete_rigid.stl"
    {"fifo": lambda: os.mkfifo(target), "symlink": lambda: target.symlink_to(real), "folder": target.mkdir}[kind]()
    before = snapshot(out)
    code, so, err = run(["generate", D4, "--out", out], capsys)
    one_line_error(code, err, "d4_discrete_rigid.stl", "only new or regular files")
    assert snapshot(out) == before and real.read_text() == "keep"


def test_output_that_is_the_design_file_is_refused(tmp_path, capsys):
    design = tmp_path / "d.toml"
    design.write_text(D4.read_text())
    code, out, err = run(["audit", design, "--json", design], capsys)
    one_line_error(code, err, "is an input of this run")
    assert design.read_text() == D4.read_text()


# -- --json - ---------------------------------------------------------------------------------------


def test_json_dash_writes_the_json_to_stdout_and_the_summary_to_stderr(tmp_path):
    r = wgcad("audit", D4, "--json", "-", cwd=tmp_path)
    assert r.returncode in (0, 1), r.stderr
    doc = json.loads(r.stdout)  # stdout is exactly one JSON document
    assert doc["design"].startswith("D4") and "min_clearance_um" in doc
    assert "clearance audit" in r.stderr and "minimum clearance" in r.stderr
    assert os.listdir(tmp_path) == []  # no file named "-"
    q = wgcad("audit", D4, "--json", "-", "--quiet", cwd=tmp_path)
    quiet = json.loads(q.stdout)
    assert q.stderr == "" and quiet.pop("elapsed_s") > 0 and doc.pop("elapsed_s") > 0 and quiet == doc


def test_full_stdout_is_a_one_line_error():
    with open("/dev/full", "w") as full:
        r = subprocess.run(
            [sys.executable, "-m", "wgcad", "audit", str(D4), "--json", "-", "--quiet"],
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
        )
    one_line_error(r.returncode, r.stderr, "standard output", "No space left on device")


def test_reader_closing_the_pipe_is_a_quiet_exit():
    # `wgcad audit ... --json - | head -c 0`: the reader is gone before wgcad writes
    p = subprocess.Popen(
        [sys.executable, "-m", "wgcad", "audit", str(D4), "--json", "-", "--quiet"],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 141 and err == ""


def _run_in_python(code: str):
    return subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_a_run_on_a_pipe_writes_its_whole_output_and_its_exit_code():
    """``python -m wgcad`` writing to a pipe (block-buffered): the whole JSON document reaches the reader and the
    exit code is the command's; a bad flag exits 2 with nothing on stdout."""
    prelude = f"import sys; from wgcad.cli import run; sys.argv = ['wgcad', 'audit', {str(D4)!r}"
    r = _run_in_python(prelude + ", '--json', '-']; run()")
    assert r.returncode in (0, 1), r.stderr
    assert json.loads(r.stdout)["worst"]  # the whole document reached the pipe
    r = _run_in_python(prelude + ", '--no-such-flag']; run()")
    assert r.returncode == 2 and r.stdout == "" and r.stderr.count("\n") == 1


def test_both_to_stdout_is_refused(capsys):
    code, out, err = run(["audit", D4, "--json", "-", "--write-baseline", "-"], capsys)
    one_line_error(code, err, "only one of them")


# -- internal errors ---------------------------------------------------------------------------------


def test_internal_error_exit_3_one_line_no_traceback(tmp_path, capsys, monkeypatch):
    import wgcad.cli.generate

    def broken(*args, **kwargs):
        return 1 / 0

    monkeypatch.setattr(wgcad.cli.generate, "build_drive", broken)
    monkeypatch.delenv("WGCAD_TRACEBACK", raising=False)
    code, out, err = run(["generate", D4, "--out", tmp_path / "o"], capsys)
    assert code == 3 and err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("wgcad: internal error: ZeroDivisionError: division by zero at wgcad/")
    assert "please report it" in err and "WGCAD_TRACEBACK=1" in err and "on stderr" in err
    assert not (tmp_path / "o").exists()
    monkeypatch.setenv("WGCAD_TRACEBACK", "1")
    code, out, err = run(["generate", D4, "--out", tmp_path / "o"], capsys)
    assert (
        code == 3
        and "Traceback (most recent call last)" in err
        and err.rstrip().splitlines()[-1].startswith("wgcad: internal error")
    )
    monkeypatch.delenv("WGCAD_TRACEBACK")
    code, out, err = run(["--traceback", "generate", D4, "--out", tmp_path / "o"], capsys)
    assert code == 3 and "Traceback (most recent call last)" in err
    # after the subcommand too, where users put their other flags
    code, out, err = run(["generate", D4, "--out", tmp_path / "o", "--traceback"], capsys)
    assert code == 3 and "Traceback (most recent call last)" in err


def test_interference_keeps_exit_1_and_bad_input_exit_2(capsys):
    code, out, err = run(["audit", TEMPLATES / "d1_involute_nominal.toml", "--step-deg", "3", "--quiet"], capsys)
    assert code == 1 and err == ""  # the teaching template's nominal teeth interfere (the README's example of exit 1)


# -- several designs in one folder, re-runs ----------------------------------------------------------


def files_of(folder: Path):
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))


def test_two_designs_share_a_folder_without_replacing_each_others_report(tmp_path, capsys):
    out = tmp_path / "out"
    for name in ("d4_discrete", "d2"):
        code, so, se = run(["generate", TEMPLATES / f"{name}.toml", "--out", out, "--no-stl", "--quiet"], capsys)
        assert code == 0, se
    for name in ("d4_discrete", "d2"):
        rep = json.loads((out / f"{name}.report.json").read_text())
        assert rep["files"] == [f"{name}.dxf", f"{name}.report.json"]
    assert files_of(out) == ["d2.dxf", "d2.report.json", "d4_discrete.dxf", "d4_discrete.report.json"]


def test_rerun_removes_only_its_own_previous_files(tmp_path, capsys):
    out = tmp_path / "out"
    code, so, se = run(["generate", D4, "--out", out, "--quiet"], capsys)  # DXF, two STLs, report
    assert code == 0, se
    # things wgcad did not write (or wrote for another design) stay
    (out / "notes.txt").write_text("mine")
    (out / "d4_discrete_old.stl").write_text("a file of the same design's name that wgcad did not write")
    code, so, se = run(["generate", TEMPLATES / "d2.toml", "--out", out, "--no-stl", "--quiet"], capsys)
    assert code == 0
    code, so, se = run(["generate", D4, "--out", out, "--no-stl"], capsys)
    assert code == 0 and "removed 2 of the previous run's files" in so
    rep = json.loads((out / "d4_discrete.report.json").read_text())
    assert rep["files"] == ["d4_discrete.dxf", "d4_discrete.report.json"]
    assert files_of(out) == [
        "d2.dxf",
        "d2.report.json",
        "d4_discrete.dxf",
        "d4_discrete.report.json",
        "d4_discrete_old.stl",
        "notes.txt",
    ]
    # the folder holds exactly what each report lists, plus the files wgcad did not write
    assert set(files_of(out)) - {"d4_discrete_old.stl", "notes.txt"} == set(rep["files"]) | set(
        json.loads((out / "d2.report.json").read_text())["files"]
    )


def test_rerun_keeps_a_file_changed_since_wgcad_wrote_it(tmp_path, capsys):
    out = tmp_path / "out"
    assert run(["generate", D4, "--out", out, "--quiet"], capsys)[0] == 0
    with open(out / "d4_discrete_rigid.stl", "ab") as fp:
        fp.write(b"edited")
    code, so, se = run(["generate", D4, "--out", out, "--no-stl", "--quiet"], capsys)
    assert code == 0
    assert "warning: kept" in se and "d4_discrete_rigid.stl" in se
    assert files_of(out) == ["d4_discrete.dxf", "d4_discrete.report.json", "d4_discrete_rigid.stl"]


def test_same_name_from_another_folder_is_a_collision(tmp_path, capsys):
    other = tmp_path / "other"
    other.mkdir()
    (other / "d4_discrete.toml").write_text(edit_toml(D4.read_text(), "drive", "name", '"another D4"'))
    out = tmp_path / "out"
    assert run(["generate", D4, "--out", out, "--no-stl", "--quiet"], capsys)[0] == 0
    before = snapshot(out)
    code, so, se = run(["generate", other / "d4_discrete.toml", "--out", out, "--no-stl"], capsys)
    one_line_error(code, se, "another design file named d4_discrete", "--force")
    assert snapshot(out) == before
    code, so, se = run(["generate", other / "d4_discrete.toml", "--out", out, "--no-stl", "--quiet", "--force"], capsys)
    assert code == 0
    assert json.loads((out / "d4_discrete.report.json").read_text())["design"] == "another D4"


# -- refused runs create no folder; special output folders -------------------------------------------


def test_refused_audit_leaves_no_folder(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(edit_toml(D4.read_text(), "drive", "module", "-1.0"))
    code, out, err = run(
        ["audit", bad, "--json", tmp_path / "new" / "deeper" / "r.json", "--plot", tmp_path / "pics" / "p"], capsys
    )
    one_line_error(code, err, "drive.module")
    assert sorted(os.listdir(tmp_path)) == ["bad.toml"]


def test_refused_generate_leaves_no_folder(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(edit_toml(D4.read_text(), "drive", "z_flex", "0"))
    code, out, err = run(["generate", bad, "--out", tmp_path / "a" / "b"], capsys)
    one_line_error(code, err, "drive.z_flex")
    assert sorted(os.listdir(tmp_path)) == ["bad.toml"]


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs a proc file system")
@pytest.mark.parametrize(
    "cmd",
    [
        ["generate", D4, "--out", "/proc"],
        ["kinematics", TEMPLATES / "d3_external.toml", "--out", "/proc/x"],
        ["audit", D4, "--json", "/proc/wgcad.json"],
    ],
)
def test_proc_as_output_gets_the_right_message(capsys, cmd):
    code, out, err = run(cmd, capsys)
    one_line_error(code, err, "proc file system")
    assert "No such file" not in err


# -- interrupted runs ----------------------------------------------------------------------------------


def _start_and_wait_for_temp(out: Path, tmp_path: Path):
    """Start a long generate and return it once its batch holds temporary files in ``out``."""
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "wgcad",
            "generate",
            str(TEMPLATES / "d1_involute.toml"),
            "--out",
            str(out),
            "--generator-angle",
            "0,10",
            "--quiet",
        ],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a shell without job control starts background jobs with SIGINT ignored, and the child would inherit
        # that (Ctrl-C is then meant not to reach it): the run under test gets the default disposition back
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if out.is_dir() and any(n.startswith(".d1_involute.dxf.") and n.endswith(".tmp") for n in os.listdir(out)):
            return p
        if p.poll() is not None:
            break
        time.sleep(0.01)
    p.kill()
    pytest.fail(f"no temporary file appeared (exit {p.poll()}): {p.stderr.read()}")


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_signal_mid_export_cleans_up(tmp_path, sig):
    out = tmp_path / "out"
    p = _start_and_wait_for_temp(out, tmp_path)
    signum = getattr(signal, sig)
    p.send_signal(signum)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 128 + signum, err
    assert err.count("\n") == 1 and "temporary files removed" in err and "Traceback" not in err
    assert not out.exists()  # the folder the run created goes too: nothing was written


def test_killed_run_leftovers_are_removed_by_the_next_run(tmp_path, capsys):
    out = tmp_path / "out"
    p = _start_and_wait_for_temp(out, tmp_path)
    p.send_signal(signal.SIGKILL)  # no chance to clean up
    p.communicate(timeout=60)
    left = [n for n in os.listdir(out) if n.endswith(".tmp")]
    assert left, "SIGKILL left nothing to clean up: the test did not test anything"
    (out / "user.tmp").write_text("not wgcad's")
    code, so, se = run(["generate", TEMPLATES / "d4_discrete.toml", "--out", out, "--no-stl", "--quiet"], capsys)
    assert code == 0, se
    assert sorted(os.listdir(out)) == [
        ".d4_discrete.wgcad-files.json",
        "d4_discrete.dxf",
        "d4_discrete.report.json",
        "user.tmp",
    ]


# -- every subcommand: bad input is one line, exit 2, nothing written ---------------------------------

BAD_RUNS = [
    ["generate", "{bad}"],
    ["generate", "{missing}"],
    ["generate", D4, "--chord-tol-um", "0"],
    ["generate", D4, "--out", "{file}/sub"],
    ["generate", D4, "--bogus"],
    ["audit", "{bad}", "--json", "r/x.json"],
    ["audit", "{missing}"],
    ["audit", D4, "--step-deg", "nan"],
    ["audit", D4, "--sections", "0"],
    ["audit", D4, "--json", "/dev/null"],
    ["audit", D4, "--baseline", "{missing}"],
    ["kinematics", "{bad}"],
    ["kinematics", "{missing}"],
    ["kinematics", TEMPLATES / "d3_external.toml", "--out", "{file}"],
    ["kinematics", D4, "--omega-h", "-1"],
    [],
    ["nosuchcommand"],
]


@pytest.mark.parametrize("argv", BAD_RUNS, ids=lambda a: " ".join(str(x) for x in a)[-60:] or "(none)")
def test_bad_input_subprocess_one_line_exit_2_nothing_written(tmp_path, argv):
    work = tmp_path / "work"
    work.mkdir()
    (work / "bad.toml").write_text(edit_toml(D4.read_text(), "drive", "module", "0.0"))
    (work / "file").write_text("a regular file")
    subs = {"{bad}": "bad.toml", "{missing}": "missing.toml", "{file}": "file"}
    args = [str(a) for a in argv]
    for k, v in subs.items():
        args = [a.replace(k, v) for a in args]
    before = snapshot(work)
    r = wgcad(*args, cwd=work)
    one_line_error(r.returncode, r.stderr)
    assert r.stdout == ""
    assert snapshot(work) == before


# -- help texts, imports per command --------------------------------------------------------------------


def test_every_flag_and_argument_has_help():
    import argparse

    parser = build_parser()
    parsers = [parser]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            parsers += list(action.choices.values())
    missing = []
    for p in parsers:
        for action in p._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            if not action.help or not action.help.strip():
                missing.append(f"{p.prog} {'/'.join(action.option_strings) or action.dest}")
    assert missing == []
