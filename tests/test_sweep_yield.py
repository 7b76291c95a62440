"""The yield of a sweep against a case with a known answer, its confidence intervals against their definitions, the shared KE table against per-sample tables."""

import math

import numpy as np
import pytest
from conftest import TEMPLATES
from scipy.stats import binom

from wgcad.accuracy import ke as K
from wgcad.design import load_design
from wgcad.design.schema import parse_design
from wgcad.drive import build_drive
from wgcad.placement.imperfect import Imperfections
from wgcad.sweep.runner import run_sweep
from wgcad.sweep.sampling import sample_design_data, sample_values
from wgcad.sweep.spec import parse_spec
from wgcad.sweep.store import Store
from wgcad.sweep.summary import clopper_pearson, summarize, wilson
from wgcad.sweep.tasks import columns_of, run_sample

AS = 180.0 / math.pi * 3600.0
D4 = str(TEMPLATES / "d4_discrete.toml")
F_HI = 60.0  # um: top of the uniform run-out
LIMIT = 45.0  # arcsec


@pytest.mark.parametrize("n", [1, 7, 40, 1000])
def test_clopper_pearson_against_its_definition(n):
    # the bounds solve P(X >= k | lo) = a/2 and P(X <= k | hi) = a/2 (binomial tails, scipy.stats.binom)
    for k in sorted({0, 1, n // 3, n - 1, n}):
        lo, hi = clopper_pearson(k, n, 0.95)
        if k > 0:
            assert binom.sf(k - 1, n, lo) == pytest.approx(0.025, rel=1e-6)
        else:
            assert lo == 0.0
        if k < n:
            assert binom.cdf(k, n, hi) == pytest.approx(0.025, rel=1e-6)
        else:
            assert hi == 1.0
    # closed forms at the ends: k = 0 -> 1 - (a/2)^(1/n)
    assert clopper_pearson(0, n)[1] == pytest.approx(1 - 0.025 ** (1 / n), rel=1e-9)


def test_wilson_textbook_value():
    # 8 of 10 at 95 %: 0.4902 .. 0.9433 (Newcombe 1998, table I)
    lo, hi = wilson(8, 10)
    assert lo == pytest.approx(0.4902, abs=1e-4) and hi == pytest.approx(0.9433, abs=1e-4)


@pytest.fixture(scope="module")
def d4():
    return build_drive(load_design(D4))


@pytest.fixture(scope="module")
def threshold_um(d4):
    """Run-out F* at which D4's largest KE reaches LIMIT, by bisection on the KE model called directly."""
    tab = K.contact_table(d4, Imperfections(rigid_runout=F_HI * 1e-3), 16)

    def ke(F):
        return K.kinematic_error(d4, Imperfections(rigid_runout=F * 1e-3), table=tab).ke_pp * AS

    a, b = 0.0, F_HI
    assert ke(a) < LIMIT < ke(b)
    # monotone on a 10 um grid (so one threshold splits pass from fail)
    vals = [ke(F) for F in np.arange(0.0, F_HI + 1, 10.0)]
    assert all(np.diff(vals) > 0)
    while b - a > 1e-4:
        m = 0.5 * (a + b)
        a, b = (m, b) if ke(m) < LIMIT else (a, m)
    return 0.5 * (a + b)


def test_yield_against_the_known_fraction(threshold_um, tmp_path):
    # one parameter, uniform on [0, 60] um, and a limit it crosses once at F*: the exact yield is F* / 60
    spec = parse_spec(
        {
            "sweep": {"name": "known", "design": D4, "samples": 48, "seed": 2026},
            "figures": {"record": ["ke_pp_arcsec"]},
            "parameters": {"imperfections": {"rigid_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": F_HI}}},
            "limits": {"ke_pp_arcsec": {"max": LIMIT}},
        }
    )
    run_sweep(spec, tmp_path, workers=0, batch=16)
    pl = spec.payload()
    cols = Store(tmp_path, pl["fingerprint"], columns_of(pl), spec.total).read()
    F = cols["imperfections.rigid_runout_um"]
    s = summarize(spec, cols, conf=0.99)
    exact = threshold_um / F_HI
    # every sample on the right side of the threshold (none within the bisection's 1e-4 um of it)
    assert np.min(np.abs(F - threshold_um)) > 1e-4
    passed = cols["ke_pp_arcsec"] <= LIMIT
    np.testing.assert_array_equal(passed, F < threshold_um)
    assert s["yield"]["pass"] == int((F < threshold_um).sum()) and s["yield"]["of"] == 48
    lo, hi = s["yield"]["ci"]
    assert lo <= exact <= hi
    assert 0.2 < exact < 0.9  # the case tests something: the threshold is inside the range
    # the failure driver is the only parameter, positively (more run-out, more failures)
    assert s["sensitivity"][0]["parameter"] == "imperfections.rigid_runout_um" and s["sensitivity"][0]["failure"] > 0.5


def _own_table_ke(pl, i):
    d = parse_design(sample_design_data(pl["design"], pl["parameters"], sample_values(pl, i)))
    return K.kinematic_error(build_drive(d), Imperfections.from_spec(d.imperfections), 16).ke_pp * AS


def test_shared_table_gives_the_per_sample_table_result():
    # The worker's contact table is built once for the sweep's largest amplitudes (more candidate
    # contacts, a superset refined); each sample's KE against `wgcad ke`'s table built for that sample
    # alone, on the bundled D2 tolerance spec (the model's regime: errors well below the tooth overlap,
    # docs/models.md 6.2). Measured: within 1.2e-8 arcsec (finite-difference sensitivities of contacts
    # refined in one table and not the other); 1e-6 arcsec leaves margin and is 4 orders below the
    # 0.01 arcsec the summary prints.
    from wgcad.sweep.spec import load_spec

    pl = load_spec(TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml").payload()
    for i in (0, 1):
        row = run_sample(pl, i)
        assert row["status"] == "ok" and abs(row["ke_pp_arcsec"] - _own_table_ke(pl, i)) < 1e-6


def test_per_sample_table_is_wgcad_ke_exactly():
    # figures.ke_table = "per_sample": the table wgcad ke would build for each drive, so the same number
    spec = parse_spec(
        {
            "sweep": {"name": "own", "design": D4, "samples": 2, "seed": 9},
            "figures": {"record": ["ke_pp_arcsec"], "ke_table": "per_sample"},
            "parameters": {
                "imperfections": {
                    "rigid_runout_um": {"distribution": "uniform", "lo": 0.0, "hi": 40.0},
                    "flex_eccentricity_um": {"distribution": "uniform", "lo": 0.0, "hi": 15.0},
                    "cam_offset_fixed_um": {"distribution": "uniform", "lo": 0.0, "hi": 20.0},
                }
            },
        }
    )
    pl = spec.payload()
    for i in (0, 1):
        assert run_sample(pl, i)["ke_pp_arcsec"] == _own_table_ke(pl, i)


def test_samples_outside_the_ke_model_fail_with_the_reason_and_leave_the_yield(tmp_path, capsys):
    # issue 19: D2 as first templated interferes so deeply at its open end that the linear KE model does not hold
    # (accuracy/ke.py DEEP_OVERLAP); a sweep of its KE recorded the figure anyway and printed a yield over it.
    # Such a sample now fails with the model's reason, records no KE, and the yield says it has none to count.
    from wgcad.cli import main

    design = TEMPLATES.parent / "tests" / "designs" / "d2_imperfect_nominal.toml"
    text = (TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml").read_text().replace("samples = 10000", "samples = 2")
    text = text.replace('design = "../d2_imperfect.toml"', f'design = "{design}"')
    spec = tmp_path / "d2_small.toml"
    spec.write_text(text)
    assert main(["sweep", str(spec), "--workers", "0", "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "0 computed" in out and "2 failed in a model" in out
    assert "KE outside the linear error model" in out
    assert "YIELD not defined" in out and "YIELD 1" not in out and "YIELD 9" not in out


def test_design_study_is_a_table_not_a_distribution(tmp_path):
    # issue 23: the design study printed mean, sd, percentiles and a 54-100 % interval of six designs on a grid,
    # and drew histograms of them; a grid prints one row per design and draws the surface only
    from conftest import TEMPLATES

    from wgcad.export.pictures.sweep import sweep_pngs
    from wgcad.sweep.spec import load_spec
    from wgcad.sweep.summary import format_summary

    spec = load_spec(TEMPLATES / "sweeps" / "d1_design_study.toml")
    run_sweep(spec, tmp_path, workers=0)
    pl = spec.payload()
    cols = Store(tmp_path, pl["fingerprint"], columns_of(pl), spec.total).read()
    summ = summarize(spec, cols)
    assert summ["kind"] == "grid"
    text = format_summary(summ)
    assert "grid of 6 designs" in text and "mean" not in text and "interval" not in text, text
    rows = [line for line in text.splitlines() if line.startswith("    ") and ("yes" in line or "NO" in line)]
    assert len(rows) == 6
    assert set(sweep_pngs(spec, cols, summ)) == {"sweep_surface.png"}
