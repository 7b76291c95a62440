"""The files of ``wgcad generate`` as a library call (issue 20: the CLI only parses, calls and prints)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import wgcad
from wgcad.errors import OutputError
from wgcad.export.files.drive import angle_tag, planned_names

ROOT = Path(__file__).resolve().parent.parent
D1 = ROOT / "templates" / "d1_involute.toml"


def test_library_call_writes_what_the_cli_writes(tmp_path):
    drive = wgcad.build_drive(wgcad.load_design(D1))
    seen = []
    res = wgcad.write_drive_files(
        drive, D1, tmp_path / "lib", angles_deg=[15.0], stl=False, progress=lambda f, s: seen.append(f)
    )
    names = sorted(p.name for p in (tmp_path / "lib").iterdir())
    assert names == sorted(planned_names("d1_involute", [15.0], stl=False))
    assert [p.name for p in res.files] == [
        "d1_involute.dxf",
        "d1_involute_phip015_000.dxf",
        "d1_involute_phip015_000.png",
        "d1_involute.report.json",
    ]
    assert res.removed == [] and res.kept == []
    assert seen == sorted(seen) and seen[-1] == 1.0  # the progress only moves forward, and ends
    cli = subprocess.run(
        [
            sys.executable,
            "-m",
            "wgcad",
            "generate",
            str(D1),
            "--no-stl",
            "--generator-angle",
            "15",
            "--out",
            str(tmp_path / "cli"),
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert cli.returncode == 0, cli.stderr
    assert json.loads(cli.stdout) == res.report
    for p in res.files:
        assert (tmp_path / "cli" / p.name).read_bytes() == p.read_bytes(), p.name


def test_library_call_refuses_before_any_work(tmp_path):
    drive = wgcad.build_drive(wgcad.load_design(D1))
    (tmp_path / "d1_involute.report.json").mkdir()  # a folder where the report goes
    with pytest.raises(OutputError, match="report.json"):
        wgcad.write_drive_files(drive, D1, tmp_path, stl=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d1_involute.report.json"]


def test_angle_tags_name_distinct_angles_apart():
    assert angle_tag(15.0) == "p015_000" and angle_tag(-2.5) == "m002_500"
    assert angle_tag(1.0) != angle_tag(1.0004)  # closer than the 1e-3 deg tag: six decimals then
