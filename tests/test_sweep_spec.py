"""Sweep specs validated like designs (one-line errors, exit 2) and samples reproducible from seed and index alone."""

import json
import math

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.cli import main
from wgcad.errors import DesignError
from wgcad.sweep.sampling import sample_values, split_index
from wgcad.sweep.spec import load_spec, parse_spec

D4 = str(TEMPLATES / "d4_discrete.toml")


def _spec(**over):
    data = {
        "sweep": {"name": "t", "design": D4, "samples": 4, "seed": 7},
        "figures": {"record": ["ke_pp_arcsec"]},
        "parameters": {
            "imperfections": {
                "rigid_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 30.0},
                "rigid_runout_phase_deg": {"distribution": "normal", "mean": 0.0, "sd": 90.0},
            }
        },
        "limits": {"ke_pp_arcsec": {"max": 40.0}},
    }
    for k, v in over.items():
        if v is None:
            data.pop(k)
        else:
            data[k] = v
    return data


def test_template_spec_is_valid():
    s = load_spec(TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml")
    assert s.total == 10000 and s.record == ("ke_pp_arcsec", "lost_motion_min_arcsec", "ke_deep_overlap_fraction")
    assert {p.key for p in s.parameters} >= {"flex_runout_um", "rigid_runout_phase_deg"}
    d = load_spec(TEMPLATES / "sweeps" / "d1_design_study.toml")
    assert d.total == 6 and d.grid_points == 6 and not d.random


@pytest.mark.parametrize(
    "change, field, words",
    [
        ({"sweep": {"design": D4, "seed": 1, "sampels": 3}}, "sweep.sampels", "did you mean 'samples'"),
        ({"sweep": {"design": D4}}, "sweep.seed", "required"),
        ({"figures": {"record": ["ke_pp_arcsecs"]}}, "figures.record", "did you mean 'ke_pp_arcsec'"),
        ({"figures": {"record": ["entry_gap_um@500Nm"]}}, "figures.record", "[bearing]"),
        ({"figures": {"record": ["ke_pp_arcsec"], "ke_table": "each"}}, "figures.ke_table", "shared, per_sample"),
        (
            {"parameters": {"generator": {"w0_cof": {"grid": [1.0]}}}},
            "parameters.generator.w0_cof",
            "did you mean 'generator.w0_coef'",
        ),
        (
            {"parameters": {"imperfections": {"rigid_runout_um": {"distribution": "normal", "mean": 1.0, "sd": 0.0}}}},
            "parameters.imperfections.rigid_runout_um.sd",
            "> 0",
        ),
        (
            {"parameters": {"imperfections": {"rigid_runout_um": {"distribution": "lognormal"}}}},
            "parameters.imperfections.rigid_runout_um.distribution",
            "normal, uniform, grid",
        ),
        (
            {"parameters": {"drive": {"z_flex": {"distribution": "uniform", "lo": 80, "hi": 90}}}},
            "parameters.drive.z_flex",
            "grid",
        ),
        (
            {"parameters": {"generator": {"law": {"grid": ["disc", "oval"]}}}},
            "parameters.generator.law.grid[1]",
            "harmonic",
        ),
        (
            {"parameters": {"load": {"cam_offset_um": {"distribution": "uniform", "lo": 0.0, "hi": 10.0}}}},
            "parameters.load.cam_offset_um",
            "no recorded figure depends on [load]",
        ),
        ({"limits": {"entry_gap_um": {"min": 0.0}}}, "limits.entry_gap_um", "not a recorded figure"),
        ({"limits": {"ke_pp_arcsec": {"min": 5.0, "max": 1.0}}}, "limits.ke_pp_arcsec.max", "> min"),
    ],
)
def test_bad_specs_name_the_field_and_rule(change, field, words):
    with pytest.raises(DesignError) as e:
        parse_spec(_spec(**change))
    assert e.value.field == field and words in str(e.value)


def test_cli_bad_spec_one_line_exit_2(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text(
        f'[sweep]\ndesign = "{D4}"\nseed = 1\n[figures]\nrecord = ["ke_pp_arcsec"]\n[parameters.generator.w0_coef]\ngrid = [1.1, 1.1]\n'
    )
    assert main(["sweep", str(p), "--workers", "0", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "parameters.generator.w0_coef.grid" in err[0] and "repeat" in err[0]
    assert not (tmp_path / "o").exists()  # nothing written
    assert main(["sweep", str(tmp_path / "none.toml")]) == 2
    assert "sweep spec file not found" in capsys.readouterr().err


def test_samples_depend_on_seed_and_index_only():
    spec = parse_spec(
        _spec(
            parameters={
                "generator": {"w0_coef": {"grid": [1.05, 1.1, 1.15]}},
                "imperfections": {"rigid_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 30.0}},
            },
            sweep={"design": D4, "samples": 5, "seed": 3},
        )
    )
    pl = spec.payload()
    assert spec.total == 15
    fwd = [sample_values(pl, i) for i in range(15)]
    back = [sample_values(pl, i) for i in reversed(range(15))][::-1]
    assert fwd == back
    # grid point slowest, draw fastest; every grid point sees the same draws (common random numbers)
    assert [v["generator.w0_coef"] for v in fwd] == [1.05] * 5 + [1.1] * 5 + [1.15] * 5
    assert [v["imperfections.rigid_runout_um"] for v in fwd[:5]] == [
        v["imperfections.rigid_runout_um"] for v in fwd[10:]
    ]
    assert split_index(13, 5, (3,)) == ((2,), 3)
    other = parse_spec(_spec(sweep={"design": D4, "samples": 5, "seed": 4}, parameters=spec_params(spec)))
    assert sample_values(other.payload(), 0) != fwd[0]


def spec_params(spec):
    return {
        "generator": {"w0_coef": {"grid": [1.05, 1.1, 1.15]}},
        "imperfections": {"rigid_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 30.0}},
    }


def test_distributions_have_their_moments():
    # 4000 draws: the sample mean is within 4 standard errors of the true mean (fails with p ~ 6e-5),
    # the uniform stays in its range, the normal's sd within 5 % (its standard error is ~1.1 %)
    spec = parse_spec(
        _spec(
            sweep={"design": D4, "samples": 4000, "seed": 11},
            parameters={
                "imperfections": {
                    "rigid_runout_um": {"distribution": "uniform", "lo": 10.0, "hi": 30.0},
                    "flex_runout_um": {"distribution": "normal", "mean": 50.0, "sd": 8.0},
                }
            },
        )
    )
    pl = spec.payload()
    v = [sample_values(pl, i) for i in range(4000)]
    u = np.array([x["imperfections.rigid_runout_um"] for x in v])
    g = np.array([x["imperfections.flex_runout_um"] for x in v])
    assert u.min() >= 10.0 and u.max() <= 30.0
    assert abs(u.mean() - 20.0) < 4 * (20.0 / math.sqrt(12)) / math.sqrt(4000)
    assert abs(g.mean() - 50.0) < 4 * 8.0 / math.sqrt(4000)
    assert abs(g.std() / 8.0 - 1.0) < 0.05
    # independent parameters: the draws of the two are uncorrelated (|r| < 4 / sqrt(n))
    assert abs(np.corrcoef(u, g)[0, 1]) < 4 / math.sqrt(4000)


def test_cli_run_in_process_writes_results_summary_and_pictures(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text(
        f'[sweep]\nname = "grid"\ndesign = "{D4}"\nseed = 1\nsamples = 2\n[figures]\nrecord = ["ke_pp_arcsec"]\n'
        "[parameters.generator.w0_coef]\ngrid = [1.05, 1.1]\n"
        '[parameters.imperfections.rigid_runout_um]\ndistribution = "uniform"\nlo = 0.0\nhi = 40.0\n'
        "[limits]\nke_pp_arcsec = { max = 40.0 }\n"
    )
    out = tmp_path / "o"
    assert main(["sweep", str(p), "--workers", "0", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "YIELD" in text and "4 of 4 samples stored" in text
    s = json.loads((out / "summary.json").read_text())
    assert s["counts"]["ok"] == 4 and s["grid"]["shape"] == [2]
    for name in ("sweep_histograms.png", "sweep_sensitivity.png", "sweep_surface.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # a rerun computes nothing; the summary alone reads the store
    assert main(["sweep", str(p), "--workers", "0", "--out", str(out), "--no-plots"]) == 0
    assert "0 samples computed, 4 already stored" in capsys.readouterr().out


def test_a_sample_that_fails_or_errors_is_counted_not_fatal(tmp_path, monkeypatch):
    # a model that gives up (a WgcadError that is not a rule) and a bug (any other exception) in two samples
    from wgcad.elastic.solve import ContactSolveError
    from wgcad.sweep import tasks
    from wgcad.sweep.runner import run_sweep
    from wgcad.sweep.store import Store
    from wgcad.sweep.summary import summarize

    real = tasks._ke

    def flaky(payload, data, design, drive):
        amp = design.imperfections.rigid_runout_um
        if amp > 25.0:
            raise ContactSolveError("load state: tooth positions still moving")
        if amp < 5.0:
            raise ZeroDivisionError("boom")
        return real(payload, data, design, drive)

    monkeypatch.setattr(tasks, "_ke", flaky)
    spec = parse_spec(_spec(sweep={"design": D4, "samples": 12, "seed": 3}))
    info = run_sweep(spec, tmp_path, workers=0, batch=5)
    assert info.computed == 12
    pl = spec.payload()
    cols = Store(tmp_path, pl["fingerprint"], tasks.columns_of(pl), 12).read()
    amp = cols["imperfections.rigid_runout_um"]
    np.testing.assert_array_equal(cols["status"] == "failed", amp > 25.0)
    np.testing.assert_array_equal(cols["status"] == "error", amp < 5.0)
    assert (cols["status"] == "ok").sum() == ((amp >= 5.0) & (amp <= 25.0)).sum() > 0
    assert all(r.startswith("ZeroDivisionError: boom") for r in cols["reason"][amp < 5.0])
    s = summarize(spec, cols)
    assert s["counts"]["failed"] == int((amp > 25.0).sum()) and s["counts"]["error"] == int((amp < 5.0).sum())


def test_loaded_figures_are_the_elastic_models():
    # figures under load against the elastic model called directly (wgcad audit --torque-nm's path);
    # the torque may be written 500.0 or 500
    from wgcad.design import load_design
    from wgcad.drive import build_drive
    from wgcad.elastic.model import build_model
    from wgcad.elastic.sweep import torque_sweep
    from wgcad.sweep.tasks import run_sample

    d1 = str(TEMPLATES / "d1_involute.toml")
    spec = parse_spec(
        {
            "sweep": {"design": d1, "seed": 1},
            "figures": {"record": ["entry_gap_um@500.0Nm", "teeth_in_contact@500Nm"]},
            "parameters": {"load": {"cam_offset_um": {"grid": [30.0]}}},
        }
    )
    row = run_sample(spec.payload(), 0)
    assert row["status"] == "ok", row["reason"]
    drive = build_drive(load_design(d1))
    lv = torque_sweep(build_model(drive, 3), [500.0], 30.0, drive.design.load.cam_offset_deg).levels[0]
    assert row["entry_gap_um@500.0Nm"] == 1e3 * lv.entry_gap and row["teeth_in_contact@500Nm"] == lv.teeth_in_contact
    with pytest.raises(DesignError, match="named twice"):
        parse_spec(
            {
                "sweep": {"design": d1, "seed": 1},
                "figures": {"record": ["entry_gap_um@500.0Nm", "entry_gap_um@500Nm"]},
                "parameters": {"load": {"cam_offset_um": {"grid": [30.0]}}},
            }
        )
