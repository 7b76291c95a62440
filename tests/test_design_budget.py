"""The work and memory estimate (wgcad.design.budget): close to what runs really need, and runs over the budget refused before allocating."""

import json
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest
from conftest import ROOT, TEMPLATES
from hypothesis import HealthCheck, given, settings
from test_stability import designs

from wgcad.cli import main
from wgcad.design import load_design, parse_design, with_changes
from wgcad.design.budget import (
    DEFAULT_MAX_MEMORY_MB,
    RunShape,
    check_budget,
    estimate_run,
    outline_vertices_per_tooth,
)
from wgcad.drive import build_drive, tooth_spec
from wgcad.errors import DesignError
from wgcad.profiles.gear import make_gear

NAMES = ["d1_involute", "d1_cycloidal", "d2", "d3_external", "d4_discrete"]
#: The vertex estimate is an upper envelope (fitted on random designs): never below the real count.
#: How far above varies with the tooth shape (shift, pressure angle, truncation change the flank
#: length at equal sqrt(m / tol), which one coefficient cannot follow): on the templates within
#: VERTS_FACTOR, on random designs within VERTS_FACTOR_RANDOM and typically (median) within 3x.
VERTS_FACTOR = 7.0
VERTS_FACTOR_RANDOM = 15.0


def _per_tooth(gear) -> int:
    return len(gear.period) - 1


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("tol_um", [10.0, 1.0, 0.1, 0.01])
def test_vertex_estimate_bounds_the_templates_outlines(name, tol_um):
    d = load_design(TEMPLATES / f"{name}.toml")
    est = outline_vertices_per_tooth(d.tooth.form, d.drive.module, tol_um * 1e-3)
    for which in ("flexspline", "rigid"):
        n = _per_tooth(make_gear(tooth_spec(d, which), tol_um * 1e-3))
        assert n <= est <= VERTS_FACTOR * n, (which, n, est)


_seen = []


@settings(
    derandomize=True,
    max_examples=int(__import__("os").environ.get("WGCAD_BUDGET_EXAMPLES", "60")),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(designs())
def _random_counts(data):
    try:
        d = parse_design(data)
        build_drive(d, tol=1e-2)
    except DesignError:
        return
    for tol in (1e-2, 1e-3, 1e-4):
        est = outline_vertices_per_tooth(d.tooth.form, d.drive.module, tol)
        for which in ("flexspline", "rigid"):
            n = _per_tooth(make_gear(tooth_spec(d, which), tol))
            assert n <= est <= VERTS_FACTOR_RANDOM * n, (which, tol, n, est)
            _seen.append(est / n)


def test_vertex_estimate_bounds_random_designs():
    _seen.clear()
    _random_counts()
    assert len(_seen) >= 60  # not vacuous
    assert float(np.median(_seen)) <= 3.0, np.median(_seen)


def test_refused_before_any_large_allocation():
    # 2998 + 3000 teeth of module 20 at a 0.001 um chord tolerance: ~5e7 vertices; judged from the design
    d = load_design(TEMPLATES / "d1_involute.toml")
    big = with_changes(
        d,
        drive={"module": 20.0, "z_flex": 2998, "z_rigid": 3000, "face_width": 30.0},
        flexspline={"rim_thickness": 28.0},
    )
    tracemalloc.start()
    try:
        with pytest.raises(DesignError) as e:
            build_drive(big, tol=1e-6)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert e.value.field == "--max-memory-mb" and "raise --max-memory-mb" in str(e.value)
    assert peak < 1e6, peak  # bytes: nothing sampled


def test_no_budget_means_no_refusal_and_the_estimate_grows_with_the_work():
    d = load_design(TEMPLATES / "d4_discrete.toml")
    a = estimate_run(d, 1e-3, run=RunShape(angles=720, sections=3))
    b = estimate_run(d, 1e-4, run=RunShape(angles=720, sections=3))
    c = estimate_run(d, 1e-3, run=RunShape(angles=7200, sections=3))
    bare = RunShape(angles=720, sections=3, use_period=False, use_waves=False, use_mirror=False, bound=False)
    full = estimate_run(d, 1e-3, run=bare)
    assert a.memory_mb < b.memory_mb and a.memory_mb < c.memory_mb < full.memory_mb * 10
    assert a.memory_mb < full.memory_mb
    assert check_budget(full, None) is full
    with pytest.raises(DesignError, match="more than the budget of 1 MB; raise --max-memory-mb"):
        check_budget(a, 1.0)


def test_cli_refuses_over_budget_and_the_flag_raises_it(tmp_path, capsys):
    design = TEMPLATES / "d4_discrete.toml"
    code = main(["audit", str(design), "--max-memory-mb", "50", "--json", str(tmp_path / "o" / "a.json")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--max-memory-mb: this run needs about" in err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())
    code = main(["generate", str(design), "--max-memory-mb", "50", "--out", str(tmp_path / "g")])
    assert code == 2 and "--max-memory-mb" in capsys.readouterr().err
    assert not (tmp_path / "g").exists() or not any((tmp_path / "g").iterdir())
    # the default budget admits the templates' default runs
    assert main(["audit", str(design), "--quiet"]) in (0, 1)


def test_d1_without_shortcuts_at_fine_steps_is_refused_by_default(capsys):
    # measured before this check: 10.8 GB peak, 189 s (--step-deg 0.05 --sections 3 --no-shortcuts)
    code = main(["audit", str(TEMPLATES / "d1_involute.toml"), "--step-deg", "0.05", "--no-shortcuts"])
    err = capsys.readouterr().err
    assert code == 2 and "--max-memory-mb" in err and f"budget of {DEFAULT_MAX_MEMORY_MB:g} MB" in err


# VmHWM (peak RSS of this process image): ru_maxrss would carry the forking parent's peak across exec
_CHILD = """
import json, sys
from wgcad.cli import main
code = main(sys.argv[1:])
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM:")][0].split()[1]
print(json.dumps({"code": code, "rss_mb": int(hwm) / 1024}))
"""


@pytest.mark.skipif(not __import__("os").path.exists("/proc/self/status"), reason="needs Linux /proc for the peak RSS")
@pytest.mark.parametrize(
    "argv,run",
    [
        (
            ["audit", "d1_involute", "--step-deg", "0.05", "--sections", "3", "--quiet"],
            RunShape(angles=7200, sections=3, exports=False),
        ),
        (["generate", "d4_discrete", "--chord-tol-um", "0.1", "--quiet"], RunShape(exports=True)),
    ],
)
def test_memory_estimate_is_above_the_measured_peak_and_not_far(argv, run, tmp_path):
    """Peak RSS of a real run in a fresh interpreter against the estimate made from its design."""
    name = argv[1]
    args = [argv[0], str(TEMPLATES / f"{name}.toml"), *argv[2:]]
    if argv[0] == "generate":
        args += ["--out", str(tmp_path / "o")]
    p = subprocess.run([sys.executable, "-c", _CHILD, *args], capture_output=True, text=True, cwd=ROOT, timeout=300)
    res = json.loads(p.stdout.strip().splitlines()[-1])
    assert res["code"] in (0, 1), p.stderr
    d = load_design(TEMPLATES / f"{name}.toml")
    tol = 1e-4 if "0.1" in argv else 1e-3
    drive = build_drive(d, tol=tol)
    counts = {"flexspline": _per_tooth(drive.flex), "rigid": _per_tooth(drive.rigid)}
    est = estimate_run(d, tol, run=run, vertices_per_tooth=counts).memory_mb
    # an estimate is for refusing runs: above the real peak, and within 4x of it (fitted on other runs)
    assert res["rss_mb"] <= est <= 4.0 * res["rss_mb"], (res["rss_mb"], est)


def _peak_mb(args, cwd) -> tuple[int, float]:
    """Exit code and peak RSS (VmHWM, MB) of ``wgcad ARGS`` in a fresh interpreter: the interpreter and imports count."""
    p = subprocess.run([sys.executable, "-c", _CHILD, *args], capture_output=True, text=True, cwd=cwd, timeout=300)
    res = json.loads(p.stdout.strip().splitlines()[-1])
    return res["code"], res["rss_mb"] * 1.048576  # kB of /proc to MB (the budget's unit)


TEMPLATE_FILES = sorted(p.stem for p in TEMPLATES.glob("*.toml"))


@pytest.mark.skipif(not __import__("os").path.exists("/proc/self/status"), reason="needs Linux /proc for the peak RSS")
@pytest.mark.parametrize("name", TEMPLATE_FILES)
def test_generate_estimate_is_within_2x_of_the_peak_on_every_template(name, tmp_path):
    """The figure ``generate --max-memory-mb`` is judged on (issue 43: 232 MB for a D1 run that peaked at 93 MiB,
    so a budget of 150 MB refused it): above the measured peak and at most twice it, with and without STL."""
    d = load_design(TEMPLATES / f"{name}.toml")
    for extra, stl in (([], True), (["--no-stl"], False)):
        args = ["generate", str(TEMPLATES / f"{name}.toml"), "--out", str(tmp_path / f"o{stl}"), "--quiet", *extra]
        code, peak = _peak_mb(args, ROOT)
        assert code == 0
        est = estimate_run(d, 1e-3, run=RunShape(exports=stl)).memory_mb  # what build_drive checks for generate
        assert peak <= est <= 2.0 * peak, (name, stl, peak, est)


@pytest.mark.skipif(not __import__("os").path.exists("/proc/self/status"), reason="needs Linux /proc for the peak RSS")
@pytest.mark.parametrize("name", TEMPLATE_FILES)
def test_audit_estimate_is_within_2x_of_the_peak_on_every_template(name):
    """A default audit (0.5 deg, 3 sections) against the estimate build_drive checks once the gears are built."""
    code, peak = _peak_mb(["audit", str(TEMPLATES / f"{name}.toml"), "--quiet"], ROOT)
    assert code in (0, 1)
    d = load_design(TEMPLATES / f"{name}.toml")
    drive = build_drive(d, tol=1e-3)
    counts = {"flexspline": _per_tooth(drive.flex), "rigid": _per_tooth(drive.rigid)}
    run = RunShape(angles=720, sections=3, exports=False)
    est = estimate_run(d, 1e-3, run=run, vertices_per_tooth=counts).memory_mb
    assert peak <= est <= 2.0 * peak, (name, peak, est)
