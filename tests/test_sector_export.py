"""`wgcad sector`: files written (heights table and plot both ways, motion law CSV/PNG, audit, DXF, STL), read back and checked."""

import csv
import json

import ezdxf
import numpy as np
import pytest
import trimesh
from conftest import TEMPLATES

from wgcad.cli import main
from wgcad.export.dxf import audit_dxf, read_dxf

D4 = TEMPLATES / "d4_sectored.toml"


@pytest.fixture(scope="module")
def run_sim(tmp_path_factory):
    out = tmp_path_factory.mktemp("sector")
    code = main(["sector", str(D4), "--out", str(out), "--heights", "simulated", "--step-deg", "1", "--json"])
    return code, out


def test_outputs_written(run_sim):
    code, out = run_sim
    assert code == 0  # no tip-to-tip left with the simulated heights
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        f"d4_sectored_{s}"
        for s in (
            "heights.csv",
            "heights.png",
            "motion.csv",
            "motion.png",
            "sector_audit.png",
            "sector_rigid.dxf",
            "sector_rigid.stl",
            "sector.json",
        )
    )
    for p in out.glob("*.png"):
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_stl_watertight_after_read_back(run_sim):
    _, out = run_sim
    m = trimesh.load(out / "d4_sectored_sector_rigid.stl")
    assert m.is_watertight and m.is_volume
    # volume = (rim disc - toothed hole) x face width, to float32 STL rounding
    r = read_dxf(out / "d4_sectored_sector_rigid.dxf")
    o = r["RIGID_SECTORED"]["outlines"][0]
    x, y = o[:, 0], o[:, 1]
    hole = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    R = r["RIGID_RIM"]["circles"][0][2]
    assert m.volume == pytest.approx((np.pi * R**2 - hole) * 5.0, rel=2e-3)  # rim circle polygon vs true circle: < 1e-3


def test_dxf_closed_after_read_back(run_sim):
    _, out = run_sim
    path = out / "d4_sectored_sector_rigid.dxf"
    assert audit_dxf(path) == 0
    doc = ezdxf.readfile(path)
    polys = [e for e in doc.modelspace() if e.dxftype() == "LWPOLYLINE"]
    assert len(polys) == 1 and all(p.closed for p in polys)
    o = read_dxf(path)["RIGID_SECTORED"]["outlines"][0]
    import shapely

    assert shapely.Polygon(o).is_valid


def test_exported_outline_lies_in_a_symmetric_band(run_sim):
    # the DXF's sectored outline (read back) against the same gear drawn at 0.001 um chords: within the
    # 1 um tolerance on either side, and its area error well below that of chords through points of the
    # curves (all on one side: a systematic error of about the tolerance times half the length); measured
    # on this template 0.0044 against 0.058 mm^2
    import shapely

    from wgcad.design import load_design
    from wgcad.drive import build_drive, tooth_spec
    from wgcad.profiles.gear import make_gear
    from wgcad.profiles.sector import TeethByHeight, sector_layout, sectored_outline

    _, out = run_sim
    o = read_dxf(out / "d4_sectored_sector_rigid.dxf")["RIGID_SECTORED"]["outlines"][0]
    design = load_design(D4)
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    sp = tooth_spec(design, "rigid")
    with open(out / "d4_sectored_heights.csv") as fh:
        heights = np.array(
            [float(r["built_mm"]) for r in csv.DictReader(fh)]
        )  # 1e-7 mm rounding: far below the tolerance
    fine = sectored_outline(lay, TeethByHeight(sp, make_gear(sp, 1e-6), 1e-6), heights)
    one_sided = sectored_outline(lay, TeethByHeight(sp, drive.rigid, drive.tol), heights)
    F = shapely.Polygon(fine)
    assert (
        shapely.Polygon(o).exterior.hausdorff_distance(F.exterior) <= drive.tol + 2e-6
    )  # + the fine outline's and the heights' rounding
    err_band = abs(shapely.Polygon(o).area - F.area)
    err_one = abs(shapely.Polygon(one_sided).area - F.area)
    assert err_band < 0.25 * err_one


def test_heights_table_both_ways(run_sim):
    _, out = run_sim
    rows = list(csv.DictReader(open(out / "d4_sectored_heights.csv")))
    assert len(rows) == 86
    for r in rows:
        cf, sim, diff = float(r["closed_form_mm"]), float(r["simulated_mm"]), float(r["simulated_minus_closed_um"])
        assert diff == pytest.approx(1e3 * (sim - cf), abs=1e-3)
        assert float(r["built_mm"]) == pytest.approx(sim, abs=1e-6)
    summ = json.loads((out / "d4_sectored_sector.json").read_text())
    p = summ["closed_form_parameters"]
    assert {"r_fix_mm", "r_cr_mm", "h_s_mm", "W0_mm", "beta_deg", "generator_angle_rule"} <= p.keys()
    assert summ["audit_built"]["tip_to_tip"] is False and summ["audit_full_height"]["tip_to_tip"] is True


def test_motion_csv_matches_hand_count(run_sim):
    _, out = run_sim
    rows = list(csv.DictReader(open(out / "d4_sectored_motion.csv")))
    a = np.array([float(r["generator_angle_deg"]) for r in rows])
    g = np.array([float(r["output_rotation_deg"]) for r in rows])
    dwell = np.array([r["phase"] == "dwell" for r in rows])
    assert g[-1] - g[0] == pytest.approx(-2 * 360 / 84, abs=1e-6)
    # dwell samples: 2 x 19 pitches of 360/84 deg out of 360, sampled every 0.1 deg (+-1 sample at each of 4 ends)
    assert dwell.sum() == pytest.approx(2 * 19 * 360 / 84 / 0.1, abs=4)
    assert np.ptp(g[dwell & (a < 180)]) < 1e-9


def test_full_heights_exit_1(tmp_path, capsys):
    code = main(["sector", str(D4), "--out", str(tmp_path), "--heights", "full", "--step-deg", "1", "--no-stl"])
    so = capsys.readouterr().out
    assert code == 1 and "TIP-TO-TIP" in so
    assert not (tmp_path / "d4_sectored_sector_rigid.stl").exists()


def test_library_call_writes_what_the_cli_wrote(run_sim, tmp_path):
    # issue 20: the CLI only parses, calls and prints; a library user gets the same files
    from wgcad.design import load_design
    from wgcad.export.sector_files import write_sector_files
    from wgcad.sector.run import run_sector

    _, cli_out = run_sim
    res = run_sector(load_design(D4), "simulated", None, 1.0, None)
    summ, files = write_sector_files(res, D4, tmp_path, stl=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in files)
    assert "d4_sectored_sector_rigid.stl" not in {p.name for p in files}
    for p in files:
        if p.suffix in (".csv", ".dxf"):
            assert p.read_bytes() == (cli_out / p.name).read_bytes(), p.name
    cli_summ = json.loads((cli_out / "d4_sectored_sector.json").read_text())
    drop = ("timing_s", "audit_full_height", "audit_built")  # their run times differ
    assert {k: v for k, v in summ.items() if k not in drop} == {k: v for k, v in cli_summ.items() if k not in drop}
    assert summ["audit_built"]["min_tip_clearance_um"] == cli_summ["audit_built"]["min_tip_clearance_um"]
