"""The audit's findings are typed records in internal units; the report layer alone converts and words them (issue 8)."""

import math

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.clearance.engine import AuditSettings, audit
from wgcad.clearance.findings import FIGURES, Finding
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.report.audit import audit_json, audit_summary, entry_json, worst_json


def test_report_layer_converts_units_of_a_hand_made_finding():
    f = Finding(
        "min_clearance",
        -0.0123456,
        "exact",
        tooth_angle=math.radians(5.0),
        section_z=30.0,
        location="working flank",
        generator_angle=math.radians(39.5),
        tooth=25,
        polygon_value=-0.0125,
        details={
            "mirror": (math.radians(-5.0), "non-working flank"),
            "sample_tooth_angle": math.radians(-5.0),
            "overlap_area": 1.5e-4,
        },
    )
    w = worst_json(f)
    assert w["clearance_um"] == -12.3456 and w["polygon_clearance_um"] == -12.5
    assert w["tooth_angle_deg"] == 5.0 and w["mirror"] == {"tooth_angle_deg": -5.0, "location": "non-working flank"}
    assert w["overlap_area_um2"] == 150.0 and w["section_z_mm"] == 30.0 and w["method"] == "exact"
    gap = Finding("entry_gap", float("nan"), "exact")
    crossing = Finding("entry_crossing", float("nan"), "exact")
    pinch = Finding("entry_pinch", float("nan"), "exact")
    e = entry_json(gap, crossing, pinch, "entry (+phi)")
    assert e["tooth_angle_deg"] is None and e["pinch_um"] is None and e["tip_to_tip_risk"] is False
    assert e["crossing_um"] is None and e["kind"] is None
    gap = Finding(
        "entry_gap",
        -1.5e-3,
        "exact",
        tooth_angle=math.radians(-47.5),
        section_z=30.0,
        location="tip",
        details={"edge": "working", "kind": "crossing"},
    )
    crossing = Finding(
        "entry_crossing", -1.5e-3, "exact", tooth_angle=math.radians(-47.5), section_z=30.0, details={"edge": "working"}
    )
    e = entry_json(gap, crossing, pinch, "entry (-phi)")
    assert (
        e["tooth_angle_deg"] == -47.5
        and e["crossing_um"] == -1.5
        and e["edge"] == "working"
        and e["kind"] == "crossing"
    )


def test_unknown_figure_or_method_is_refused():
    with pytest.raises(ValueError):
        Finding("max_clearance", 0.0, "exact")
    with pytest.raises(ValueError):
        Finding("entry_gap", 0.0, "guess")


@pytest.mark.parametrize("refine", [True, False])
def test_audit_returns_one_finding_per_figure_and_the_json_is_shaped_from_them(refine):
    drive = build_drive(load_design(TEMPLATES / "d1_cycloidal.toml"))
    z_b = drive.design.drive.z_rigid
    angles = np.arange(8) * (2 * np.pi / z_b) / 8  # one mesh period
    res = audit(drive, AuditSettings(angles=angles, sections=drive.sections(3), refine=refine))
    assert set(res.findings) == set(FIGURES)
    assert all(isinstance(f, Finding) and f.figure == k for k, f in res.findings.items())
    worst = res.findings["min_clearance"]
    assert worst.method == ("exact" if refine else "polygon")
    # the refined figure is within the polygon-curve difference of the polygon one (2 chord tolerances)
    assert abs(worst.value - worst.polygon_value) <= 2 * drive.tol + 1e-12
    doc = audit_json(res)
    assert doc["min_clearance_um"] == round(1e3 * worst.value, 4)
    assert doc["worst"]["tooth_angle_deg"] == round(math.degrees(worst.tooth_angle), 6)
    gap = res.findings["entry_gap"]
    assert doc["entry_gap_um"] == round(1e3 * gap.value, 4)
    assert doc["entry"]["section_z_mm"] == round(gap.section_z, 6)
    text = audit_summary("D1 cycloidal", doc)
    assert f"{doc['min_clearance_um']:.3f} um" in text and f"{doc['entry_gap_um']:.3f} um" in text
