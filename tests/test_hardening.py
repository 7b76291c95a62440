"""Odd but possible inputs: every one gets a one-line error naming its field, a distinct exit code, no traceback (issue 21)."""

from __future__ import annotations

import tomllib

import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.cli import main
from wgcad.design import load_design
from wgcad.errors import DesignError

HUGE = "1" + "0" * 400  # a TOML integer no float can hold


def _number_keys(path):
    data = tomllib.loads(path.read_text())
    for table, keys in data.items():
        if not isinstance(keys, dict):
            continue
        for key, value in keys.items():
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                yield table, key


CASES = [
    (name, t, k)
    for name in ("d1_involute", "d2_imperfect", "d4_sectored")
    for t, k in _number_keys(TEMPLATES / f"{name}.toml")
]


@pytest.mark.parametrize("name,table,key", CASES, ids=[f"{n}-{t}.{k}" for n, t, k in CASES])
def test_a_huge_integer_in_any_number_key_is_refused_naming_it(tmp_path, name, table, key):
    path = tmp_path / "huge.toml"
    path.write_text(edit_toml((TEMPLATES / f"{name}.toml").read_text(), table, key, HUGE))
    with pytest.raises(DesignError) as e:
        load_design(path)
    assert f"{table}.{key}" in str(e.value) and "401-digit" in str(e.value)


def test_a_huge_integer_on_the_command_line_path_exits_2(tmp_path, capsys):
    path = tmp_path / "huge.toml"
    path.write_text(edit_toml((TEMPLATES / "d1_involute.toml").read_text(), "drive", "face_width", HUGE))
    assert main(["audit", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "drive.face_width" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "table,key", [("sweep", "samples"), ("sweep", "seed"), ("parameters.imperfections.flex_runout_um", "mean")]
)
def test_a_huge_integer_in_a_sweep_spec_is_refused_naming_it(tmp_path, table, key):
    from wgcad.sweep.spec import load_spec

    src = (TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml").read_text()
    text = src.replace(f"[{table}]\n", f"[{table}]\n{key} = {HUGE}\n", 1)
    lines, seen = [], set()
    for line in text.splitlines():  # the original key further down the table goes (a TOML key once only)
        k = line.split("=")[0].strip()
        if k == key and line.strip() != f"{key} = {HUGE}" and (table, key) not in seen:
            seen.add((table, key))
            continue
        lines.append(line)
    path = tmp_path / "sweeps" / "spec.toml"
    path.parent.mkdir()
    path.write_text("\n".join(lines) + "\n")
    (tmp_path / "d2_imperfect.toml").write_text((TEMPLATES / "d2_imperfect.toml").read_text())
    with pytest.raises(DesignError) as e:
        load_spec(path)
    assert key in str(e.value) and "401-digit" in str(e.value)


def test_ke_of_a_drive_whose_teeth_never_touch_exits_4(tmp_path, capsys):
    # D2 with the rigid gear's shift reversed: the audit accepts it (its teeth clear by ~180 um) but nothing
    # drives the output, so there is no KE: a model's answer (exit 4, one line), not an internal error
    path = tmp_path / "apart.toml"
    path.write_text(edit_toml((TEMPLATES / "d2_imperfect.toml").read_text(), "rigid", "shift", "-3.3"))
    assert main(["ke", str(path)]) == 4
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not driven" in err and "Traceback" not in err


def test_sector_refuses_a_step_beyond_its_memory_budget(tmp_path, capsys):
    # 1e-6 deg asked for 113 GiB before it failed (MemoryError, exit 3); the estimate refuses it up front, and
    # --max-memory-mb moves the budget
    out = tmp_path / "out"
    assert main(["sector", str(TEMPLATES / "d4_sectored.toml"), "--step-deg", "1e-6", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--step-deg" in err and "MB" in err and not out.exists()
    args = ["sector", str(TEMPLATES / "d4_sectored.toml"), "--step-deg", "0.02", "--out", str(out), "--max-memory-mb"]
    assert main([*args, "100"]) == 2
    assert "budget of 100 MB" in capsys.readouterr().err


def _baseline(tmp_path, capsys):
    b = tmp_path / "b.json"
    assert main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--write-baseline", str(b), "--quiet"]) == 0
    capsys.readouterr()
    return b


@pytest.mark.parametrize(
    "edit,words",
    [
        (lambda d: d.update(settings=5), "settings must be a JSON object"),
        (lambda d: d["settings"].update(step_deg="abc"), "settings.step_deg"),
        (lambda d: d["settings"].update(sections=2.5), "settings.sections"),
        (lambda d: d["figures"]["min_clearance_um"].update(tol="abc"), "figures.min_clearance_um.tol"),
        (lambda d: d["figures"]["min_clearance_um"].update(value=[1, 2]), "figures.min_clearance_um.value"),
        (lambda d: d["figures"]["min_clearance_um"].update(tol=-1), "tol must be >= 0"),
        (lambda d: d["figures"].update(extra=5), "figures.extra must be an object"),
    ],
)
def test_a_hostile_baseline_is_refused_in_one_line(tmp_path, capsys, edit, words):
    import json

    b = _baseline(tmp_path, capsys)
    doc = json.loads(b.read_text())
    edit(doc)
    b.write_text(json.dumps(doc))
    assert main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--baseline", str(b), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err and "Traceback" not in err


def test_a_baseline_figure_of_nan_is_refused(tmp_path, capsys):
    b = _baseline(tmp_path, capsys)
    b.write_text(b.read_text().replace('"tol": 0.001', '"tol": NaN', 1))
    assert main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--baseline", str(b), "--quiet"]) == 2
    assert "NaN" in capsys.readouterr().err


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_baseline_that_is_not_a_regular_file_is_refused_without_reading(tmp_path, capsys, kind):
    import os

    if kind == "fifo":
        path = tmp_path / "fifo.json"
        os.mkfifo(path)  # reading it would wait for a writer forever
    else:
        path = "/dev/zero"  # reading it would never end
    assert main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--baseline", str(path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a regular file" in err


@pytest.mark.parametrize(
    "flag,value", [("--cam-offset-um", "1e6"), ("--cam-offset-um", "-1"), ("--cam-offset-deg", "400")]
)
def test_load_flags_share_their_keys_bounds(capsys, flag, value):
    args = ["audit", str(TEMPLATES / "d1_involute.toml"), "--torque-nm", "100", flag, value]
    with pytest.raises(SystemExit) as e:  # argparse's own exit for a bad flag
        main(args)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert flag in err and "[load]" in err and err.count("\n") == 1


def test_a_design_with_a_byte_order_mark_is_read(tmp_path):
    # editors on some systems save UTF-8 with a BOM; TOML then saw "Invalid statement (at line 1, column 1)"
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (TEMPLATES / "d4_discrete.toml").read_bytes())
    assert load_design(path).drive.z_flex == load_design(TEMPLATES / "d4_discrete.toml").drive.z_flex


def test_a_random_sweep_without_samples_is_refused():
    from wgcad.sweep.spec import parse_spec

    spec = {
        "sweep": {"name": "x", "design": str(TEMPLATES / "d2_imperfect.toml"), "seed": 1},
        "figures": {"record": ["ke_pp_arcsec"]},
        "parameters": {"imperfections": {"flex_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 20.0}}},
    }
    with pytest.raises(DesignError, match="sweep.samples: required"):
        parse_spec(spec)


def test_refusals_after_the_design_is_read_leave_no_folder(tmp_path, capsys):
    # the output folder used to be created before the work (sector, parts, ke, the load audit): a refusal then
    # left it empty behind (the long fuzz run found it on `wgcad sector` of a design without [sectors])
    out = tmp_path / "s"
    assert main(["sector", str(TEMPLATES / "d1_involute.toml"), "--out", str(out)]) == 2
    assert not out.exists()
    apart = tmp_path / "apart.toml"
    apart.write_text(edit_toml((TEMPLATES / "d2_imperfect.toml").read_text(), "rigid", "shift", "-3.3"))
    assert main(["ke", str(apart), "--json", str(tmp_path / "k" / "ke.json")]) == 4
    assert not (tmp_path / "k").exists()
    capsys.readouterr()
