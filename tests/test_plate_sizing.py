"""The cup's diaphragm sized for fatigue (wgcad.rating.plate_sizing): the part set exports the plate the datasheet
rates, that plate meets the criterion, and a plate the design gives that fails is named in a warning."""

from __future__ import annotations

import json
from math import pi, sqrt
from pathlib import Path

import numpy as np
import pytest
from conftest import d1_with_parts

from wgcad.cli import main
from wgcad.design.files import load_design
from wgcad.design.parts import PartsSpec, load_parts, part_sizes
from wgcad.drive import build_drive
from wgcad.rating.diaphragm import diaphragm_stress
from wgcad.rating.fatigue import strength
from wgcad.rating.flexspline import stress_setup
from wgcad.rating.plate_sizing import plate_of, sized_parts

ROOT = Path(__file__).resolve().parent.parent
#: the bundled templates with a cup whose [parts] leaves the diaphragm to be derived
DERIVED = [
    "d1_involute",
    "d1_involute_nominal",
    "d1_conjugate",
    "d1_conjugate_modified",
    "d1_cycloidal",
    "d1_double_arc",
]


def _drive(path):
    return build_drive(load_design(path))


def _strength(drive):
    d = drive.design
    return strength(d.material, d.flexspline.rim_thickness, d.drive.face_width)


def _goodman_by_hand(drive, values) -> float:
    """Goodman's safety of the plate of ``values`` at [load] rated_torque_nm, written out from its formulas
    (docs/models.md 10.1, 10.3): amplitude over S_e plus the von Mises mean with the tube shear T / (2 pi r^2 h)
    over S_u, the smaller of hub and wall."""
    d = drive.design
    st = _strength(drive)
    p = plate_of(drive, values)
    psi, hub, wall = diaphragm_stress(drive.law, p, d.material.youngs_modulus_gpa * 1e3, d.material.poisson)
    T = d.load.rated_torque_nm
    out = []
    for r, s in ((p.r_i, hub), (p.r_o, wall)):
        amp, mean = 0.5 * (s.max() - s.min()), 0.5 * (s.max() + s.min())
        tau = 1e3 * T / (2.0 * pi * r**2 * p.h)
        out.append(1.0 / (amp / st.endurance + sqrt(max(mean, 0.0) ** 2 + 3.0 * tau**2) / st.ultimate))
    return min(out)


@pytest.mark.parametrize("name", DERIVED)
def test_the_derived_diaphragm_meets_the_criterion_the_geometric_one_fails(name):
    """On every D1 variant the geometric default (bolts near the wall: a 14 mm annulus on D1) fails Goodman at the rated
    torque; the sized plate meets it, by the formulas written out here, within the cup's geometry."""
    path = ROOT / "templates" / f"{name}.toml"
    drive = _drive(path)
    need = drive.design.load.fatigue_safety_min
    plain = part_sizes(load_parts(path), drive)
    sized = sized_parts(load_parts(path), drive)
    assert _goodman_by_hand(drive, plain.values) < need
    assert _goodman_by_hand(drive, sized.values) >= need
    assert not [n for n in sized.notes if n.startswith("diaphragm")]
    # bounded by the geometry: a bolt circle inside the cup, clear of the hub bore by half a hole
    r_in = drive.flex_rim_radius
    bc, hole = sized.cup_bolt_circle_diameter, sized.cup_bolt_hole_diameter
    assert 0.5 * sized.hub_bore_diameter + hole <= 0.5 * bc - 0.5 * hole + 1e-9
    assert 0.5 * bc + hole <= r_in + 1e-9
    assert 0.5 * sized.shell_thickness - 1e-9 <= sized.diaphragm_thickness <= plain.diaphragm_thickness
    # the exported cup wall is the wall the models rate
    assert sized.shell_thickness == pytest.approx(drive.design.material.cup_wall_thickness_mm)
    assert "sized for fatigue" in sized.rules["diaphragm_thickness"]


def test_the_search_takes_the_outermost_circle_that_meets_it():
    """The bolt circle stops at the first step inward (0.5 mm steps of the annulus' outer limit) that meets the
    criterion: the plate at the circle the bolts of one step further out take fails it."""
    from wgcad.design.bolting import choose_bolts

    path = ROOT / "templates" / "d1_involute.toml"
    drive = _drive(path)
    sized = sized_parts(load_parts(path), drive)
    need = drive.design.load.fatigue_safety_min
    T = drive.design.load.rated_torque_nm
    r_hub = 0.5 * sized.hub_bore_diameter
    r_hi = drive.flex_rim_radius
    while True:  # the limits whose bolt circles lie outside the sized one
        c = choose_bolts(T, r_hub, r_hi, "cup")
        if 2.0 * c.radius_mm <= sized.cup_bolt_circle_diameter + 0.05:
            break
        outer = {**sized.values, "cup_bolt_circle_diameter": round(np.floor(2.0 * c.radius_mm / 0.05 + 1e-9) * 0.05, 6)}
        assert _goodman_by_hand(drive, outer) < need
        r_hi -= 0.5
    assert sized.diaphragm_thickness == part_sizes(PartsSpec(), drive).diaphragm_thickness  # kept: the circle sufficed


def _parts_json(path, tmp_path, capsys) -> dict:
    out = tmp_path / "parts"
    assert main(["parts", str(path), "--out", str(out), "--format", "dxf", "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("name", [*DERIVED, "d2"])
def test_the_datasheet_rates_the_plate_parts_exports(name, tmp_path, capsys):
    """The rating's stress set-up (the plate every datasheet row uses) and ``wgcad parts --json`` (the cup
    exported) have the same diaphragm: thickness, bolt circle and cup wall."""
    path = ROOT / "templates" / f"{name}.toml"
    drive = _drive(path)
    from wgcad.rating.notch import root_concentration

    kt = root_concentration(drive.flex, drive.flex_rim_radius)
    setup = stress_setup(drive, kt.kt, _strength(drive))
    doc = _parts_json(path, tmp_path, capsys)
    sizes = doc["sizes_mm"]
    assert setup.plate.h == sizes["diaphragm_thickness"]
    assert 2.0 * setup.plate.r_i == pytest.approx(sizes["cup_bolt_circle_diameter"], abs=1e-12)
    assert setup.plate.r_o == pytest.approx(drive.flex_rim_radius + 0.5 * setup.t_cup, abs=1e-12)
    if setup.t_cup != sizes["shell_thickness"]:  # D2: a 1.4 mm wall on a 1.4 mm rim would reach the roots
        assert name == "d2" and sizes["shell_thickness"] == pytest.approx(setup.t_cup - 0.05, abs=1e-12)
        assert any(w.startswith("cup wall: [parts] shell_thickness 1.35 mm") for w in doc["warnings"])


def test_a_given_diaphragm_that_fails_is_named_in_a_warning(tmp_path, capsys):
    """A 0.1 mm plate the design gives: the torque's shear alone (3000 N m over a 0.1 mm plate) fails it; wgcad
    parts keeps the size and warns, naming the diaphragm, in its text and in its JSON warnings."""
    path = d1_with_parts(tmp_path, "diaphragm_thickness = 0.1")
    doc = _parts_json(path, tmp_path, capsys)
    assert doc["sizes_mm"]["diaphragm_thickness"] == 0.1
    warn = [w for w in doc["warnings"] if w.startswith("diaphragm")]
    assert len(warn) == 1 and "below [load] fatigue_safety_min" in warn[0] and "diaphragm_thickness" in warn[0]
    assert main(["parts", str(path), "--out", str(tmp_path / "t"), "--format", "dxf"]) == 0
    assert "WARNING: diaphragm (0.1 mm thick" in capsys.readouterr().out
    # the warning's figure is the criterion's
    drive = _drive(path)
    sized = sized_parts(load_parts(path), drive)
    assert f"Goodman safety {_goodman_by_hand(drive, sized.values):.2f}" in warn[0]


def test_a_shell_other_than_the_modelled_wall_is_named(tmp_path):
    path = d1_with_parts(tmp_path, "shell_thickness = 1.0")
    sized = sized_parts(load_parts(path), _drive(path))
    assert any(n.startswith("cup wall: [parts] shell_thickness 1 mm") for n in sized.notes)
