"""Issue 25: double-circular-arc ("common tangent") teeth (docs/models.md 2.4) and their conjugate rigid gear."""

import dataclasses

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.clearance import AuditSettings, audit
from wgcad.design import load_design
from wgcad.drive import build_drive, tooth_spec
from wgcad.errors import DesignError
from wgcad.profiles.gear import make_gear


def _flank(gear):
    """The upper flank's pieces in order: convex arc, common tangent, concave arc (the arcs off the gear's axis)."""
    lo, hi = gear.flank_radii
    out = []
    for p in gear.pieces:
        if p.kind == "arc" and np.allclose(p.center, 0.0, atol=1e-12):
            continue
        ends = [float(np.hypot(*q)) for q in (p.start, p.end)]
        if p.start[1] > 0 and p.end[1] > 0 and all(lo - 1e-9 <= r <= hi + 1e-9 for r in ends):
            out.append(p)
    return out


def _unit(v):
    v = np.asarray(v, dtype=float).reshape(-1)
    return v / np.linalg.norm(v)


@pytest.mark.parametrize("which", ["flexspline", "rigid"])
def test_the_double_arc_tooth_is_what_its_parameters_say(which):
    """D1's double-arc teeth, external (flexspline) and internal (the design's own rigid gear): the flank is a convex
    arc of radius rho_a, a straight tangent of length l and a concave arc of rho_f, tangent-continuous where they meet
    (unit tangents equal to 1e-12); the tangent passes through the datum circle r + x m where the tooth is half the
    datum's pitch thick less the thinning, inclined by delta against the radial line there; the convex arc ends on
    the tip circle. Exact thickness (the circle met by the arcs and the line) agrees with the polyline's within the
    1 um chords."""
    design = load_design(TEMPLATES / "d1_double_arc.toml")
    design = dataclasses.replace(design, rigid=dataclasses.replace(design.rigid, flanks="form"))
    sp = tooth_spec(design, which)
    g = make_gear(sp)
    conv, line, conc = _flank(g)[:3]
    m = sp.module
    assert conv.kind == "arc" and conv.radius == pytest.approx(1.5 * m, rel=1e-12)
    assert line.kind == "line" and np.hypot(*(line.end - line.start)) == pytest.approx(0.2 * m, rel=1e-12)
    assert conc.kind == "arc" and conc.radius == pytest.approx(2.0 * m, rel=1e-12)
    for a, b in ((conv, line), (line, conc)):
        assert np.hypot(*(a.end - b.start)) < 1e-12
        ta = _unit(a.deriv(np.array([a.t1]))) * np.sign(a.t1 - a.t0 if a.kind == "arc" else 1.0)
        tb = _unit(b.deriv(np.array([b.t0]))) * np.sign(b.t1 - b.t0 if b.kind == "arc" else 1.0)
        assert np.abs(ta - tb).max() < 1e-12
    r_p = g.r + sp.shift * m
    mid = 0.5 * (line.start + line.end)
    assert np.hypot(*mid) == pytest.approx(r_p, abs=1e-12)
    assert float(np.arctan2(mid[1], mid[0])) == pytest.approx((np.pi * r_p / sp.z - sp.thinning) / (2 * r_p), abs=1e-15)
    e_r = mid / np.hypot(*mid)
    d = _unit(line.end - line.start)
    assert np.degrees(np.arccos(abs(float(d @ e_r)))) == pytest.approx(20.0, abs=1e-9)
    assert np.hypot(*conv.start) == pytest.approx(g.r_a, abs=1e-12)
    R = np.linspace(*g.flank_radii, 9)[1:-1]
    hp = g.half_period
    r, a = np.hypot(*hp.T), np.arctan2(hp[:, 1], hp[:, 0])
    on = (r > g.flank_radii[0] + 1e-9) & (r < g.flank_radii[1] - 1e-9)
    o = np.argsort(r[on])
    poly = np.interp(R, r[on][o], a[on][o])
    # a chord within tol of the curve (normal to it) is within tol / cos(i) of it along the circle, i the flank's
    # inclination against the radius there: tan(i) = R d(psi)/dR, from the exact half angle
    h = 1e-6
    slope = R * (g.half_angle(R + h) - g.half_angle(R - h)) / (2 * h)
    assert np.all(np.abs(g.half_angle(R) - poly) * R < g.tol * np.sqrt(1 + slope**2))
    assert g.half_angle(np.array([r_p]))[0] == pytest.approx((np.pi * r_p / sp.z - sp.thinning) / (2 * r_p), abs=1e-14)


@pytest.mark.parametrize(
    "key, value, field",
    [
        ("convex_radius_coef", "0.2", "tooth.convex_radius_coef"),
        ("concave_radius_coef", "0.2", "tooth.concave_radius_coef"),
        ("tangent_length_coef", "1.9", "tooth.tangent_length_coef"),
    ],
)
def test_a_double_arc_that_cannot_be_built_names_its_key(tmp_path, key, value, field):
    text = edit_toml((TEMPLATES / "d1_double_arc.toml").read_text(), "tooth", key, value)
    text = edit_toml(edit_toml(text, "rigid", "flanks", '"form"'), "rigid", "conjugate_clearance_um", None)
    p = tmp_path / "d.toml"
    p.write_text(text)
    with pytest.raises(DesignError) as e:
        build_drive(load_design(p))
    assert e.value.field == field, (e.value.field, e.value.rule)


def test_double_arc_keys_need_the_double_arc_form(tmp_path, template_text):
    p = tmp_path / "d.toml"
    p.write_text(edit_toml(template_text("d1_involute"), "tooth", "convex_radius_coef", "1.0"))
    with pytest.raises(DesignError) as e:
        load_design(p)
    assert e.value.field == "tooth.convex_radius_coef"


def test_the_conjugate_of_a_double_arc_tooth_touches_at_its_section():
    """templates/d1_double_arc.toml without its set-back and taper: the rigid gear made by envelope for the
    double-arc flexspline at z = 18 mm, audited there over a whole generator turn (0.5 deg, exact): contact without
    interference, no dead travel; the coned cup's open end then interferes (polygon figure -59.6 um)."""
    design = load_design(TEMPLATES / "d1_double_arc.toml")
    design = dataclasses.replace(
        design,
        rigid=dataclasses.replace(design.rigid, conjugate_clearance_um=0.0),
        flexspline=dataclasses.replace(design.flexspline, face_modification="none", face_taper_um_per_mm=None),
    )
    d = build_drive(design)
    assert d.rigid.spec.form == "conjugate" and d.flex.spec.form == "double_arc"
    st = AuditSettings(angles=np.deg2rad(np.arange(720) * 0.5), sections=np.array([18.0]), interference_tol=1e-3)
    res = audit(d, st)
    assert not res.interference and -1e-5 < res.min_clearance < 1e-3, res.min_clearance
    assert res.findings["min_clearance"].method == "exact"
    assert audit(d, dataclasses.replace(st, sections=np.array([0.0]))).min_clearance < -20e-3


def test_every_command_runs_on_the_double_arc_template(tmp_path, capsys):
    """generate, audit, the load audit, ke, parts and rating run on d1_double_arc.toml; the flexspline's drawing
    writes its flanks as arcs and lines (tangent arcs: no polyline approximation is needed)."""
    from wgcad.cli import main

    t = str(TEMPLATES / "d1_double_arc.toml")
    runs = [
        (["generate", t, "--out", str(tmp_path / "g"), "--no-stl", "--quiet"], {0}),
        (["audit", t, "--quiet", "--sections", "1"], {0}),  # tapered and set back: clear along the face
        (["audit", t, "--torque-nm", "0,500", "--quiet"], {0, 1}),
        (["ke", t, "--per-mesh", "4"], {0}),
        (["parts", t, "--out", str(tmp_path / "p"), "--format", "dxf", "--quiet"], {0}),
        (["rating", t], {0}),
    ]
    for args, codes in runs:
        assert main(args) in codes, args
        assert "Traceback" not in capsys.readouterr().err
    import ezdxf

    doc = ezdxf.readfile(tmp_path / "p" / "d1_double_arc_flexspline.dxf")
    data = "\n".join(e.dxf.text for e in doc.modelspace().query("TEXT") if e.dxf.layer == "GEAR_DATA")
    assert "double_arc" in data or "double-arc" in data
