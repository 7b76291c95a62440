"""Issue 25, spatial teeth: a coned cup's flexspline teeth offset along the face (docs/models.md 13.4)."""

import dataclasses

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.clearance import AuditSettings, audit
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.errors import DesignError
from wgcad.placement.law import pose_from_displacements, tooth_pose, transform

ANGLES = np.deg2rad(np.arange(720) * 0.5)


def _design(text: str, tmp_path, name="d.toml"):
    p = tmp_path / name
    p.write_text(text)
    return load_design(p)


@pytest.mark.parametrize(
    "table, key, value, extra, field",
    [
        ("rigid", "face_modification", '"depth"', None, "rigid.face_modification"),
        ("flexspline", "face_modification", '"linear"', None, "flexspline.face_taper_um_per_mm"),
        (
            "flexspline",
            "face_modification",
            '"depth"',
            ("face_taper_um_per_mm", "3.0"),
            "flexspline.face_taper_um_per_mm",
        ),
        ("flexspline", "face_modification", '"sideways"', None, "flexspline.face_modification"),
        (
            "flexspline",
            "face_taper_um_per_mm",
            "101.0",
            ("face_modification", '"linear"'),
            "flexspline.face_taper_um_per_mm",
        ),
    ],
)
def test_bad_face_modification_keys_name_the_field(tmp_path, template_text, table, key, value, extra, field):
    text = edit_toml(template_text("d1_involute"), table, key, value)
    if extra is not None:
        text = edit_toml(text, table, *extra)
    with pytest.raises(DesignError) as e:
        _design(text, tmp_path)
    assert e.value.field == field


def test_a_face_modification_needs_a_coned_cup(tmp_path, template_text):
    text = edit_toml(template_text("d1_involute"), "flexspline", "face_modification", '"depth"')
    text = edit_toml(edit_toml(text, "generator", "cone_length", None), "generator", "generator_z", None)
    with pytest.raises(DesignError) as e:
        _design(text, tmp_path)
    assert e.value.field == "flexspline.face_modification" and "coned" in e.value.rule


@pytest.fixture(scope="module")
def d1_depth():
    design = load_design(TEMPLATES / "d1_involute.toml")
    fs = dataclasses.replace(design.flexspline, face_modification="depth")
    return build_drive(dataclasses.replace(design, flexspline=fs))


def test_the_depth_modification_keeps_the_depth_of_engagement_along_the_face(d1_depth):
    """Closed form: on the major axis the tip of a tooth of section z stands at r_a + W0(z) + offset(z); coning
    gives W0(z) = W0 (l - z)/(l - z_h), so the depth taper W0/(l - z_h) makes that the same at every z (to
    rounding), and the offset is zero at the generator's centre line (the reference section)."""
    from wgcad.report.sections import engagement_depth

    d = d1_depth
    g = d.design.generator
    assert d.face_reference_z == g.generator_z and d.tooth_offset(g.generator_z) == 0.0
    assert d.face_taper == pytest.approx(d.design.w0 / (g.cone_length - g.generator_z), rel=1e-15)
    depths = [engagement_depth(d, z) for z in (0.0, 7.5, 18.0, 30.0)]
    assert np.ptp(depths) < 1e-12
    plain = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    assert engagement_depth(plain, 0.0) - engagement_depth(plain, 30.0) > 0.16  # 165 um without the modification
    assert d.law_at(0.0).tooth_offset == pytest.approx(-d.face_taper * 18.0, rel=1e-14)


def test_an_offset_section_places_the_tooth_moved_along_its_centre_line(d1_depth):
    """Every pose path (the law's, the clearance scene's batch of sections, the elastic model's displacements)
    places tooth point p of an offset section where the unmodified pose places p + (offset, 0)."""
    from wgcad.clearance.scene import Scene

    d = d1_depth
    local = d.flex.period
    phi = np.linspace(-1.2, 1.2, 37)
    for z in (0.0, 30.0):
        law = d.law_at(z)
        off = law.tooth_offset
        assert abs(off) > 0.05
        plain = dataclasses.replace(law, tooth_offset=0.0)
        want = transform(local + np.array([off, 0.0]), *tooth_pose(plain, phi, d.r_m, frame_angle=0.3))
        got = transform(local, *tooth_pose(law, phi, d.r_m, frame_angle=0.3))
        assert np.abs(got - want).max() < 1e-12
        st = plain.state(phi)
        got2 = transform(local, *pose_from_displacements(phi, st.w, st.v, st.theta, d.r_m, 0.3, off))
        assert np.abs(got2 - want).max() < 1e-12
    scene = Scene(d)
    zs = [0.0, 30.0]
    zi = np.arange(len(phi)) % 2
    rot, shift = scene.pose_sections(phi, zi, zs)
    for k in range(len(phi)):
        r1, s1 = scene.pose(phi[k : k + 1], zs[zi[k]])
        assert abs(rot[k] - r1[0]) < 1e-14 and np.abs(shift[k] - s1[0]).max() < 1e-12


@pytest.fixture(scope="module")
def d1_conjugate():
    return build_drive(load_design(TEMPLATES / "d1_conjugate.toml"))


def test_the_modification_evens_out_a_conjugate_pair_along_the_face(d1_conjugate):
    """D1 with its rigid gear conjugate at z = 18 mm, each face end audited alone over a whole generator turn (0.5
    deg, exact). Unmodified: -39.0 um at the open end, +18.4 um at the inner end. The depth-keeping taper (5.5
    um/mm) moves the open end's teeth in by 99 um and makes that end conjugate too (|c| below 0.1 um; measured
    -0.01), but the inner end now interferes (measured -9.3 um): coning changes the tooth's turn and tangential
    motion as well, which no offset along the centre line undoes. The balanced taper (measured 4.73 um/mm) leaves
    both ends at the same clearance (measured -5.46 / -5.45 um): the polygon search ends within two chord
    tolerances of even, and either end is within 6 um of the reference section's contact."""
    from wgcad.report.sections import balanced_taper

    d = d1_conjugate
    st = AuditSettings(angles=ANGLES, sections=np.array([0.0, 30.0]), interference_tol=1e-3)

    def ends(drive):
        return [audit(drive, dataclasses.replace(st, sections=np.array([z]))).min_clearance for z in (0.0, 30.0)]

    c_plain = ends(d)
    assert c_plain[0] < -35e-3 and c_plain[1] > 15e-3
    depth_taper = 1e3 * d.design.w0 / (d.design.generator.cone_length - d.design.generator.generator_z)
    c_depth = ends(d.with_face_taper(depth_taper))
    assert abs(c_depth[0]) < 1e-4 and c_depth[1] < -5e-3
    bal = balanced_taper(d, st)
    assert 0.0 < bal["face_taper_um_per_mm"] < depth_taper
    c = bal["min_clearance_um"]
    assert abs(c["open_end"] - c["inner_end"]) < 2.0  # two 1 um chord tolerances: the search runs on polygons
    # the worst end is better than with the depth-keeping taper (measured 5.46 against 9.31 um)
    assert max(abs(c["open_end"]), abs(c["inner_end"])) < max(abs(1e3 * x) for x in c_depth) - 2.0


def test_the_3d_check_agrees_on_modified_teeth(d1_conjugate):
    """python-fcl lofts the placed tooth through the sections' poses, offsets included: it agrees with the 2D
    figures of the depth-modified pair (whose worst spot is at the inner end)."""
    from wgcad.clearance.fcl3d import verify_worst
    from wgcad.report.check3d import check3d_document

    d = d1_conjugate.with_face_taper(5.498)
    res = audit(d, AuditSettings(angles=ANGLES, sections=np.array([0.0, 15.0, 30.0])))
    assert res.findings["min_clearance"].section_z == 30.0
    out = check3d_document(verify_worst(d, res))
    assert out["agree"], out["summary"]


def test_the_modified_flexspline_is_lofted_in_step_and_stl(tmp_path):
    """The part set of D1 with the depth modification: the flexspline's STEP reads back as one valid solid whose
    volume is the exact one (Simpson's rule on the arc outlines at both ends and mid-face: the section's area is
    quadratic in the offset, the offset linear in z) to 1e-6, its STL is watertight (trimesh) and its tips stand
    out by the offset at each end of the face (the largest vertex radius at z = 0 and z = 30 is the tip radius plus
    the offset there, within the 1 um band), 165 um apart; the drawing's data block says how the teeth move."""
    import ezdxf
    import trimesh

    from wgcad.cli import main
    from wgcad.export.formats.step import read_step, solid_props

    text = edit_toml((TEMPLATES / "d1_involute.toml").read_text(), "flexspline", "face_modification", '"depth"')
    src = tmp_path / "d1_depth.toml"
    src.write_text(text)
    out = tmp_path / "p"
    assert main(["parts", str(src), "--out", str(out), "--format", "dxf,stl,step", "--quiet"]) == 0
    import json

    info = json.loads((out / "d1_depth_parts.json").read_text())
    flex = info["parts"]["flexspline"]
    d = build_drive(load_design(src))
    shapes = read_step(out / "d1_depth_flexspline.step")
    assert len(shapes) == 1
    props = solid_props(shapes[0])
    assert props["valid"] and props["volume"] == pytest.approx(flex["volume_mm3"], rel=1e-6)
    assert props["faces"].get("GeomAbs_BSplineSurface", 0) > 0  # ruled faces between the end outlines
    mesh = trimesh.load(out / "d1_depth_flexspline.stl")
    assert mesh.is_watertight and mesh.volume == pytest.approx(flex["volume_mm3"], rel=2e-4)
    v = mesh.vertices
    bw = d.design.drive.face_width
    tips = []
    for z in (0.0, bw):
        on = np.abs(v[:, 2] - z) < 1e-6
        r = np.hypot(v[on, 0], v[on, 1]).max()
        assert abs(r - (d.flex.r_a + d.tooth_offset(z))) < 2e-3, (z, r)
        tips.append(r)
    assert tips[1] - tips[0] == pytest.approx(d.tooth_offset(bw) - d.tooth_offset(0.0), abs=2e-3)
    doc = ezdxf.readfile(out / "d1_depth_flexspline.dxf")
    data = "\n".join(e.dxf.text for e in doc.modelspace().query("TEXT") if e.dxf.layer == "GEAR_DATA")
    assert "FACE-MODIFIED" in data and "-99.0 um at z = 0" in data
    assert flex["face_modification"]["tooth_offset_um"]["z_0_mm"] == pytest.approx(-99.0, abs=0.1)


def test_the_spatial_template_clears_along_the_face():
    """templates/d1_conjugate_modified.toml: D1's conjugate pair with the balanced taper (4.734 um/mm) and the
    conjugate flanks set back by 6 um. At the conjugate section (z = 18 mm, offset 0) the pair keeps the set-back as
    its clearance (the offset of an envelope is the envelope of the offset tooth: within 0.05 um of 6 um), and
    neither face end interferes (measured +0.54 and +0.55 um, mid-face +5.9 um)."""
    d = build_drive(load_design(TEMPLATES / "d1_conjugate_modified.toml"))
    st = AuditSettings(angles=ANGLES, sections=np.array([18.0]), interference_tol=1e-3)
    c = {z: audit(d, dataclasses.replace(st, sections=np.array([z]))).min_clearance for z in (0.0, 18.0, 30.0)}
    assert abs(c[18.0] - 6e-3) < 5e-5, c
    assert c[0.0] > 0 and c[30.0] > 0, c
