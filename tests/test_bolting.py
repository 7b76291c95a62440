"""Bolt circles sized for the torque they carry (wgcad.design.bolting) and the part sizes that use them (issue 23, item 3).

The friction-grip rule against a hand computation, the choice against its
own constraints (and its minimality), and the templates: D1's bolts carry
its design torque 3000 N m ([load] rated_torque_nm) (they were 8 x 19.7 mm on the cup and 12 x 4.6 mm on the
flange, whatever the torque), D3's hub holes keep their ligaments (6.1 mm
holes left 1.9 mm walls), and an external drive lists no cup or flange.
"""

from __future__ import annotations

import math
import tomllib

import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.design.bolting import METRIC, SLIP_SAFETY, carry, choose_bolts
from wgcad.design.parts import load_parts, part_sizes
from wgcad.drive import build_drive
from wgcad.errors import DesignError


def test_carry_is_the_friction_grip_formula_by_hand():
    # 12 x M10 (A_s 58 mm^2), class 12.9 (R_p0.2 1100 MPa), preload 0.7 R_p0.2 A_s = 44,660 N, mu 0.12, r 108.5 mm:
    # T = 12 x 0.12 x 44,660 N x 0.1085 m = 6977.7 N m
    assert carry(58.0, 12, 108.5) == pytest.approx(12 * 0.12 * 0.7 * 1100.0 * 58.0 * 0.1085, rel=1e-12)
    assert carry(58.0, 12, 108.5) == pytest.approx(6977.7, abs=0.1)


@pytest.mark.parametrize("torque,r_lo,r_hi", [(3000.0, 20.1, 80.44), (800.0, 20.0, 80.0), (20.0, 5.0, 14.0)])
def test_choice_keeps_its_rules_and_is_the_smallest(torque, r_lo, r_hi):
    c = choose_bolts(torque, r_lo, r_hi, "cup")
    assert c.capacity_nm >= SLIP_SAFETY * torque
    assert c.radius_mm - c.hole_mm >= r_lo - 1e-9 and c.radius_mm + c.hole_mm <= r_hi + 1e-9  # ligaments >= hole/2
    assert 2 * c.radius_mm * math.sin(math.pi / c.count) >= 2 * c.hole_mm  # a hole apart
    # no smaller metric bolt carries the torque in up to 16 holes placed by the same rule
    for size, area, hole in METRIC:
        if size == c.size:
            break
        r = r_hi - hole
        fitting = [n for n in (6, 8, 10, 12, 16) if 2 * r * math.sin(math.pi / n) >= 2 * hole and r - hole >= r_lo]
        assert all(carry(area, n, r) < SLIP_SAFETY * torque for n in fitting), size


def test_a_torque_no_circle_carries_is_refused():
    with pytest.raises(DesignError) as e:
        choose_bolts(1e6, 5.0, 14.0, "cup")
    assert e.value.field == "parts.cup_bolt_circle_diameter"


def test_templates_bolts_carry_their_design_torque():
    for name in ("d1_involute", "d2"):
        path = TEMPLATES / f"{name}.toml"
        drive = build_drive(load_design(path))
        s = part_sizes(load_parts(path), drive)
        T = drive.design.load.rated_torque_nm
        assert not s.notes
        for prefix in ("cup", "flange"):
            n = s.values[f"{prefix}_bolt_count"]
            hole = s.values[f"{prefix}_bolt_hole_diameter"]
            area = [a for _, a, h in METRIC if h == hole][0]
            assert carry(area, n, 0.5 * s.values[f"{prefix}_bolt_circle_diameter"]) >= SLIP_SAFETY * T * 0.999
            # a derived count says its bolts; a count the template gives (D2's cup, the diaphragm its supports read)
            # has no rule, only the check above that it carries the torque
            if f"{prefix}_bolt_count" in s.rules:
                assert s.rules[f"{prefix}_bolt_count"].startswith(f"{n} x M")
            else:
                assert f"{prefix}_bolt_count" in tomllib.loads(path.read_text())["parts"]


def test_external_drive_lists_only_its_parts_sizes_and_keeps_its_ligaments():
    path = TEMPLATES / "d3_external.toml"
    drive = build_drive(load_design(path))
    s = part_sizes(load_parts(path), drive)
    assert not any(
        k.startswith(("cup", "shell", "diaphragm", "hub", "flange_outer", "flange_thickness")) for k in s.used
    )
    assert not s.notes  # the derived holes keep half a hole of wall to the bore and to the root
    r = 0.5 * s.values["flange_bolt_circle_diameter"]
    hole = s.values["flange_bolt_hole_diameter"]
    root = min(drive.rigid.r_f, drive.rigid.r_a)
    assert r - 0.5 * hole - drive.rigid_rim_radius >= 0.5 * hole and root - r - 0.5 * hole >= 0.5 * hole


def test_given_bolts_that_slip_are_warned_about(tmp_path):
    text = (TEMPLATES / "d1_involute.toml").read_text()
    path = tmp_path / "d1.toml"
    path.write_text(
        text + "\n[parts]\ncup_bolt_circle_diameter = 100\ncup_bolt_count = 6\ncup_bolt_hole_diameter = 4.5\n"
    )
    drive = build_drive(load_design(path))
    s = part_sizes(load_parts(path), drive)
    assert any("cup bolts" in n and "slip" in n for n in s.notes), s.notes
