"""The command line: outputs of `generate` and `kinematics`, one-line errors with exit code 2 and nothing written."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from conftest import TEMPLATES, edit_toml

from wgcad.cli import main
from wgcad.design import load_design
from wgcad.drive import build_drive


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


# (table, key, value, field named in the message, words of the rule)
BAD = [
    ("drive", "module", "0.0", "drive.module", "must be > 0"),
    ("drive", "module", "-0.8", "drive.module", "must be > 0"),
    ("drive", "z_flex", "0", "drive.z_flex", "at least 8"),
    ("drive", "z_rigid", "201", "drive.z_rigid", "positive multiple of drive.waves"),
    ("drive", "z_rigid", "198", "drive.z_rigid", "positive multiple of drive.waves"),
    ("drive", "modul", "0.8", "drive.modul", "did you mean 'module'"),
    ("flexspline", "shfit", "3.1", "flexspline.shfit", "did you mean 'shift'"),
    ("drive", "z_flex", '"200"', "drive.z_flex", "must be a whole number"),
    ("drive", "z_flex", "200.0", "drive.z_flex", "must be a whole number"),
    ("flexspline", "shift", "true", "flexspline.shift", "must be a number"),
    ("flexspline", "tip_radius", "81.0", "flexspline.tip_radius", "outside the root radius"),
    ("rigid", "root_radius", "82.0", "rigid.tip_radius", "inside the root radius"),
    ("flexspline", "shift", "6.0", "flexspline.shift", "pointed teeth"),
    ("flexspline", "rim_thickness", "0.0", "flexspline.rim_thickness", "must be > 0"),
    ("flexspline", "rim_thickness", "-1.4", "flexspline.rim_thickness", "must be > 0"),
    ("generator", "law", '"elliptic"', "generator.law", "must be one of"),
    ("generator", "beta_deg", "95.0", "generator.beta_deg", "(0, 90)"),
    ("rigid", "fillet_coef", "1.0", "rigid.fillet_coef", "largest that fits"),
    ("tooth", "form", '"cycloid"', "tooth.form", "must be one of involute, cycloidal"),
    ("drive", "waves", "1", "drive.waves", "must be >= 2"),
    ("generator", "offset", "2.0", "generator.offset", "used only by the ellipse law"),
    ("generator", "beta_deg", "42.0", "generator.beta_deg", "must not lie in (40.71, 49.29)"),
]


def _assert_clean_failure(code, out, err, tmp_out: Path, *words):
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("wgcad: error: ")
    assert "Traceback" not in err
    for w in words:
        assert w in err, err
    assert not tmp_out.exists() or not any(tmp_out.iterdir())


@pytest.mark.parametrize("table,key,value,field,rule", BAD)
def test_bad_design_is_one_line_exit_2_nothing_written(tmp_path, capsys, table, key, value, field, rule):
    text = edit_toml((TEMPLATES / "d1_involute.toml").read_text(), table, key, value)
    design = tmp_path / "bad.toml"
    design.write_text(text)
    out = tmp_path / "out"
    code, so, se = run(["generate", design, "--out", out], capsys)
    _assert_clean_failure(code, so, se, out, field, rule)


def test_undercut(tmp_path, capsys):
    text = (TEMPLATES / "d4_discrete.toml").read_text()
    text = edit_toml(edit_toml(text, "drive", "z_flex", "14"), "drive", "z_rigid", "16")
    text = edit_toml(text, "flexspline", "shift", "-0.5")
    (tmp_path / "u.toml").write_text(text)
    code, so, se = run(["generate", tmp_path / "u.toml", "--out", tmp_path / "o"], capsys)
    _assert_clean_failure(code, so, se, tmp_path / "o", "flexspline.shift", "undercut")


def test_missing_table_and_invalid_toml(tmp_path, capsys):
    (tmp_path / "a.toml").write_text("[drive]\nname = 'x'\n")
    code, so, se = run(["generate", tmp_path / "a.toml", "--out", tmp_path / "o"], capsys)
    _assert_clean_failure(code, so, se, tmp_path / "o", "drive.module", "is required")
    (tmp_path / "b.toml").write_text("[drive\nname = 'x'\n")
    code, so, se = run(["generate", tmp_path / "b.toml", "--out", tmp_path / "o"], capsys)
    _assert_clean_failure(code, so, se, tmp_path / "o", "not valid TOML")


def test_missing_file(tmp_path, capsys):
    code, so, se = run(["generate", tmp_path / "nope.toml", "--out", tmp_path / "o"], capsys)
    _assert_clean_failure(code, so, se, tmp_path / "o", "nope.toml", "not found")


def test_unwritable_output_folder(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("a regular file, so no folder can be made below it (works as root too)")
    out = blocker / "sub"
    code, so, se = run(["generate", TEMPLATES / "d4_discrete.toml", "--out", out], capsys)
    assert code == 2 and "not writable" in se and se.count("\n") == 1
    assert blocker.read_text().startswith("a regular file")


@pytest.mark.parametrize(
    "flag", [["--chord-tol-um", "0"], ["--chord-tol-um", "abc"], ["--generator-angle", "0,x"], ["--bogus"]]
)
def test_bad_flags(tmp_path, capsys, flag):
    with pytest.raises(SystemExit) as e:
        main(["generate", str(TEMPLATES / "d4_discrete.toml"), "--out", str(tmp_path / "o"), *flag])
    err = capsys.readouterr().err
    assert e.value.code == 2 and err.count("\n") == 1 and err.startswith("wgcad: error:")
    assert not (tmp_path / "o").exists()


@pytest.fixture(scope="module")
def d4_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("d4")
    code = main(
        ["generate", str(TEMPLATES / "d4_discrete.toml"), "--out", str(out), "--generator-angle", "0,30", "--quiet"]
    )
    assert code == 0
    return out


def test_generate_writes_everything(d4_run):
    names = sorted(p.name for p in d4_run.iterdir())
    assert names == sorted(
        [
            "d4_discrete.dxf",
            "d4_discrete_flexspline.stl",
            "d4_discrete_rigid.stl",
            "d4_discrete_phip000_000.dxf",
            "d4_discrete_phip000_000.png",
            "d4_discrete_phip030_000.dxf",
            "d4_discrete_phip030_000.png",
            "d4_discrete.report.json",
            ".d4_discrete.wgcad-files.json",
        ]
    )
    rep = json.loads((d4_run / "d4_discrete.report.json").read_text())
    for key in (
        "pitch_radius_mm",
        "tip_radius_mm",
        "root_radius_mm",
        "base_radius_mm",
        "tooth_thickness_pitch_mm",
        "space_width_pitch_mm",
    ):
        assert key in rep["flexspline"] and key in rep["rigid"]
    assert rep["drive"]["ratio_rigid_fixed"] == -43 and rep["drive"]["ratio_flexspline_fixed"] == 44
    assert {"depth_of_engagement_mm", "clearance_flex_tip_major_um", "clearance_rigid_tip_major_um"} <= set(rep["mesh"])


def test_dxf_reads_back_equal_to_outline(d4_run):
    from wgcad.export.formats.dxf import audit_dxf, read_dxf

    drive = build_drive(load_design(TEMPLATES / "d4_discrete.toml"))
    doc = read_dxf(d4_run / "d4_discrete.dxf")
    assert audit_dxf(d4_run / "d4_discrete.dxf") == 0
    from wgcad.profiles.band import gear_band_outline

    fine = build_drive(load_design(TEMPLATES / "d4_discrete.toml"), tol=1e-5)
    for (layer, gear), ref in zip((("FLEXSPLINE", drive.flex), ("RIGID", drive.rigid)), (fine.flex, fine.rigid)):
        (o,) = doc[layer]["outlines"]
        # the very vertices are stored (doubles), so equal far below the chord tolerance
        np.testing.assert_allclose(o, gear_band_outline(gear), atol=1e-9)
        # issue 8: the symmetric band, not one-sided chords: the tooth area is right to well within
        # what one-sided chords lose (they are all on the concave side: D4 loses 4.4e-4 mm^2 a tooth)
        import shapely

        exact = shapely.Polygon(ref.outline).area  # 0.01 um chords: 1e-5 of the 1 um error
        one_sided = abs(shapely.Polygon(gear.outline).area - exact)
        assert abs(shapely.Polygon(o).area - exact) < 0.2 * one_sided
    assert doc["FLEXSPLINE_RIM"]["circles"][0][2] == pytest.approx(drive.flex_rim_radius)


def test_stl_volume_is_area_times_face_width(d4_run):
    import shapely

    drive = build_drive(load_design(TEMPLATES / "d4_discrete.toml"))
    bw = drive.design.drive.face_width
    for name, gear, rim in (
        ("flexspline", drive.flex, drive.flex_rim_radius),
        ("rigid", drive.rigid, drive.rigid_rim_radius),
    ):
        mesh = trimesh.load(d4_run / f"d4_discrete_{name}.stl")
        assert mesh.is_watertight and mesh.is_volume
        from wgcad.cli import _circle
        from wgcad.profiles.band import gear_band_outline

        circle = _circle(rim, drive.tol)
        teeth = gear_band_outline(gear)  # the exported outline (symmetric band, issue 8)
        if rim < gear.r_f:
            area = shapely.Polygon(teeth, [circle]).area
        else:
            area = shapely.Polygon(circle, [teeth]).area
        # STL stores float32 (7 digits): 1e-6 relative is the bound and above float32 rounding
        assert mesh.volume == pytest.approx(area * bw, rel=1e-6)


def test_generate_is_deterministic(tmp_path):
    # separate processes with different hash seeds: set/dict order must not leak into files
    import os

    a, b = tmp_path / "a", tmp_path / "b"
    for out, seed in ((a, "1"), (b, "2")):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "wgcad",
                "generate",
                str(TEMPLATES / "d4_discrete.toml"),
                "--out",
                str(out),
                "--generator-angle",
                "10",
                "--quiet",
            ],
            env=env,
            capture_output=True,
            text=True,
        )
        assert r.returncode == 0, r.stderr
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    for name in names:
        if name.endswith(".png"):
            continue  # pictures are for people; byte identity is promised for DXF, STL and JSON
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_kinematics_external_writes_csv_and_png(tmp_path, capsys):
    code, so, se = run(["kinematics", TEMPLATES / "d3_external.toml", "--out", tmp_path, "--omega-h", "210"], capsys)
    assert code == 0, se
    assert "u_hg = 150" in so and "u_hb = -149" in so
    csv = np.loadtxt(tmp_path / "d3_external_velocities.csv", delimiter=",", skiprows=1)
    assert csv.shape[1] == 10 and np.all(np.isfinite(csv))
    # washer speed omega_h * a_w with a_w = W0 = 0.9 mm
    assert np.allclose(csv[:, 6], 210 * 0.9)
    assert (tmp_path / "d3_external_velocities.png").stat().st_size > 10_000


def test_kinematics_internal_prints_ratios(capsys, tmp_path):
    code, so, se = run(["kinematics", TEMPLATES / "d1_involute.toml", "--out", tmp_path], capsys)
    assert code == 0 and "u_hg = -100" in so and "u_hb = 101" in so
    assert not any(tmp_path.iterdir())


def test_core_is_pure():
    code = (
        "import sys, wgcad.design, wgcad.drive, wgcad.placement, wgcad.report, wgcad.profiles.gear, wgcad.laws;"
        "bad = [m for m in ('ezdxf', 'trimesh', 'manifold3d', 'fcl', 'matplotlib') if m in sys.modules]; print(bad); sys.exit(bool(bad))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_python_m_entry_point(tmp_path):
    r = subprocess.run([sys.executable, "-m", "wgcad", "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.startswith("wgcad ")


def test_each_command_lists_its_own_exit_codes(capsys):
    # issue 23: every command's help listed the audit's exit codes; each now lists those it can return
    # (the long fuzz run, benchmarks/fuzz.py, saw exactly these per command)
    import re

    # 5 wherever an optional extra can be missing (tests/test_packaging.py runs each such case)
    codes = {
        "generate": {"0", "2", "3", "5"},
        "audit": {"0", "1", "2", "3", "4", "5"},
        "kinematics": {"0", "2", "3", "5"},
        "ke": {"0", "2", "3", "4", "5"},
        "sector": {"0", "1", "2", "3", "5"},
        "parts": {"0", "2", "3", "5"},
        "sweep": {"0", "2", "3", "4", "5", "6"},
        "design": {"0", "1", "2", "3", "5", "6"},
        "templates": {"0", "2", "3"},
    }
    for cmd, want in codes.items():
        with pytest.raises(SystemExit):
            main([cmd, "--help"])
        text = capsys.readouterr().out
        listed = set(re.findall(r"^  ([0-9])    ", text.split("exit codes:")[1], flags=re.M))
        assert listed == want, (cmd, listed)
