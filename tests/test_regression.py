"""Geometry regression: baselines of every template, drift detection, and the audit command line."""

import json
import subprocess
import sys

import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.cli import main
from wgcad.regression import compare, load_baseline
from wgcad.testing import assert_matches_baseline, baseline_drifts, record_baseline

BASELINES = TEMPLATES.parent / "tests" / "baselines"
NAMES = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete", "d1_involute_nominal"]


@pytest.mark.parametrize("name", NAMES)
def test_template_matches_its_golden_baseline(name):
    assert_matches_baseline(TEMPLATES / f"{name}.toml", BASELINES / f"{name}.json")


def test_drift_is_detected_and_explained(tmp_path):
    # the same design with the flexspline thinned by 2 um: geometry and clearances move
    text = edit_toml((TEMPLATES / "d4_discrete.toml").read_text(), "flexspline", "thinning", "0.042")
    moved = tmp_path / "d4_moved.toml"
    moved.write_text(text)
    drifts = baseline_drifts(moved, BASELINES / "d4_discrete.json")
    keys = {d.key for d in drifts}
    assert "flexspline.tooth_thickness_pitch_mm" in keys and "min_clearance_um" in keys
    assert "rigid.outline_area_mm2" not in keys  # the rigid gear did not change
    with pytest.raises(AssertionError, match="flexspline.tooth_thickness_pitch_mm: expected"):
        assert_matches_baseline(moved, BASELINES / "d4_discrete.json")


def test_tolerances_come_from_the_baseline(tmp_path):
    doc = record_baseline(TEMPLATES / "d4_discrete.toml")
    current = record_baseline(TEMPLATES / "d4_discrete.toml")["figures"]
    doc["figures"]["min_clearance_um"]["value"] += 0.5
    assert [d.key for d in compare(doc, current)] == ["min_clearance_um"]
    doc["figures"]["min_clearance_um"]["tol"] = 1.0  # a looser tolerance stored in the file is honoured
    path = tmp_path / "b.json"
    path.write_text(json.dumps(doc))
    assert baseline_drifts(TEMPLATES / "d4_discrete.toml", path) == []


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_audit_clean_design_exits_0_and_writes_json_and_plots(tmp_path, capsys):
    code, so, se = run(
        ["audit", TEMPLATES / "d4_discrete.toml", "--json", tmp_path / "r.json", "--plot", tmp_path / "d4"], capsys
    )
    assert code == 0, se
    res = json.loads((tmp_path / "r.json").read_text())
    for key in (
        "min_clearance_um",
        "entry_gap_um",
        "backlash_arcmin",
        "interference",
        "worst",
        "settings",
        "elapsed_s",
    ):
        assert key in res
    assert res["interference"] is False and res["min_clearance_um"] > 0 and res["backlash_arcmin"] > 0
    s = res["settings"]
    assert s["mesh_period"] and s["identical_waves"] and s["culling"] and "sections_note" in s
    for suffix in ("profile", "vs_angle", "tightest"):
        assert (tmp_path / f"d4_{suffix}.png").stat().st_size > 10_000
    assert "minimum clearance" in so and "entry gap" in so and "backlash" in so


def test_audit_interference_exits_1(tmp_path, capsys):
    code, so, se = run(
        ["audit", TEMPLATES / "d1_involute_nominal.toml", "--step-deg", "5", "--json", tmp_path / "r.json"], capsys
    )
    res = json.loads((tmp_path / "r.json").read_text())
    assert code == 1 and res["interference"] and "INTERFERENCE" in so
    assert res["worst"]["section_z_mm"] == 0.0  # coning: the open end is the deepest


def test_write_then_check_baseline_and_drift_exit_code(tmp_path, capsys):
    base = tmp_path / "base.json"
    code, _, _ = run(["audit", TEMPLATES / "d4_discrete.toml", "--step-deg", "2", "--write-baseline", base], capsys)
    assert code == 0 and load_baseline(base)["settings"]["step_deg"] == 2.0
    code, so, _ = run(["audit", TEMPLATES / "d4_discrete.toml", "--baseline", base], capsys)
    assert code == 0 and "within their tolerances" in so
    moved = tmp_path / "moved.toml"
    moved.write_text(edit_toml((TEMPLATES / "d4_discrete.toml").read_text(), "rigid", "shift", "1.01"))
    code, so, _ = run(["audit", moved, "--baseline", base], capsys)
    assert code == 1 and "drifted beyond tolerance" in so and "rigid.outline_area_mm2" in so


@pytest.mark.parametrize(
    "flags,words",
    [
        (["--sections", "0"], "--sections"),
        (["--step-deg", "0"], "--step-deg"),
        (["--engine", "3d"], "--engine"),
        (["--baseline", "missing.json"], "baseline file not found"),
        (["--angles", "10", "--step-deg", "1"], "not allowed with"),
        (["--angles", "0"], "--angles"),
        (["--angles", "-5"], "--angles"),
    ],
)
def test_audit_bad_flags(tmp_path, capsys, flags, words):
    try:
        code = main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--json", str(tmp_path / "r.json"), *flags])
    except SystemExit as e:
        code = e.code
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and words in err
    assert not (tmp_path / "r.json").exists()


def test_progress_bar_goes_to_stderr(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "wgcad", "audit", str(TEMPLATES / "d4_discrete.toml"), "--step-deg", "5", "--progress"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and "[" in r.stderr and "#" in r.stderr and "[" not in r.stdout.splitlines()[0]
