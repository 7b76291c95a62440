"""The 3D engine (python-fcl) against closed forms and against the 2D engine (docs/models.md 5: both must agree where both apply)."""

import json
import subprocess
import sys

import numpy as np
import pytest
import shapely
import trimesh
from conftest import TEMPLATES

from wgcad.audit import RunSettings, run_audit
from wgcad.clearance import fcl3d
from wgcad.clearance.engine import Scene, tooth_clearance
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.placement import transform
from wgcad.report.audit import audit_json
from wgcad.report.check3d import check3d_document, tooth_check_document

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


@pytest.fixture(scope="module")
def d4():
    return Scene(build_drive(load_design(TEMPLATES / "d4_discrete.toml")))


@pytest.fixture(scope="module")
def d1():
    return Scene(build_drive(load_design(TEMPLATES / "d1_involute.toml")))


def box(x, y, z0=0.0, z1=1.0, local=SQUARE):
    return fcl3d.loft(local, np.zeros(2), np.array([[x, y], [x, y]]), np.array([z0, z1]))


def tm(mesh):
    return trimesh.Trimesh(mesh[0], mesh[1], process=False)


# (a) solids ------------------------------------------------------------------


def test_prism_solids_are_closed_with_the_prism_volume(d4):
    bw = d4.drive.design.drive.face_width
    assert not d4.drive.coned
    phi = np.deg2rad(40.0)
    mesh = fcl3d.flex_tooth_solid(d4, phi)
    m = tm(mesh)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    assert len(mesh[0]) == 2 * len(d4.flex_local)  # no coning: one prism, whatever n_sections
    area = shapely.Polygon(d4.place(np.array([phi]))[0]).area
    assert m.volume == pytest.approx(area * bw, rel=1e-9)
    r = tm(fcl3d.rigid_tooth_solid(d4, 5))
    assert r.is_watertight and r.is_winding_consistent
    assert r.volume == pytest.approx(d4.rigid.polygon.area * bw, rel=1e-9)


def test_coned_loft_is_closed_and_passes_through_the_sections(d1):
    bw = d1.drive.design.drive.face_width
    phi = np.deg2rad(-35.0)
    V, F = fcl3d.flex_tooth_solid(d1, phi, n_sections=9)
    N = len(d1.flex_local)
    assert V.shape == (9 * N, 3) and F.shape == (2 * N * 8 + 2 * (N - 2), 3)
    m = trimesh.Trimesh(V, F, process=False)
    assert m.is_watertight and m.is_winding_consistent
    # rigid copies of one polygon: by Cavalieri area x width, but for the twisted side
    # quads, whose slices are within the loft error of the true sections
    err = fcl3d.loft_error(d1, phi, np.linspace(0.0, bw, 9))
    assert abs(m.volume - d1.flex.polygon.area * bw) <= d1.flex.polygon.length * bw * err["twist"].max()
    assert abs(m.volume - d1.flex.polygon.area * bw) > 0  # it is there: ~1e-4 relative
    for k, z in enumerate(np.linspace(0.0, bw, 9)):
        assert np.array_equal(V[k * N : (k + 1) * N, :2], d1.place(np.array([phi]), float(z))[0])
        assert np.all(V[k * N : (k + 1) * N, 2] == z)


# (b) FCL against closed forms -------------------------------------------------


@pytest.mark.parametrize(
    "offset, z, expected",
    [
        ((1.5, 0.25), (0.0, 1.0), 0.5),  # face to face
        ((2.0, 2.5), (0.0, 1.0), np.hypot(1.0, 1.5)),  # edge to edge
        ((0.0, 0.0), (1.75, 3.0), 0.75),  # stacked along z
        ((1.3, -1.4), (1.2, 2.0), np.sqrt(0.3**2 + 0.4**2 + 0.2**2)),  # corner to corner
    ],
)
def test_fcl_distance_of_boxes(offset, z, expected):
    d, ov = fcl3d.fcl_distance(box(0.0, 0.0), box(*offset, *z))
    assert not ov and d == pytest.approx(expected, abs=1e-9)


def test_fcl_distance_of_rotated_prisms():
    # a square turned 45 deg, its corner 0.3 from the other square's face
    c = 1.0 + 0.3 + np.sqrt(0.5)
    turned = fcl3d.loft(SQUARE - 0.5, np.full(2, np.pi / 4), np.array([[c, 0.5], [c, 0.5]]), np.array([0.0, 1.0]))
    d, ov = fcl3d.fcl_distance(box(0.0, 0.0), turned)
    assert not ov and d == pytest.approx(0.3, abs=1e-9)


def test_fcl_overlap_is_detected():
    for offset in ((0.5, 0.5), (0.999, 0.0), (0.2, -0.1)):
        d, ov = fcl3d.fcl_distance(box(0.0, 0.0), box(*offset))
        assert ov and d == 0.0
    d, ov = fcl3d.fcl_distance(box(0.0, 0.0), box(1.001, 0.0))
    assert not ov and d == pytest.approx(0.001, abs=1e-9)


def test_loft_finds_a_minimum_between_sections():
    # a unit square passing a fixed square's corner along a straight slanted path: the
    # sampled sections miss the closest approach, the loft (and FCL) does not
    local = SQUARE
    shift = np.array([[2.0, -1.2], [2.0, 1.2]])  # x from 2: gap 1 face to face at mid-height
    moving = fcl3d.loft(local, np.zeros(2), shift, np.array([0.0, 1.0]))
    fixed = box(0.0, 0.0, 0.0, 1.0)
    d, ov = fcl3d.fcl_distance(fixed, moving)
    sampled = min(shapely.distance(shapely.Polygon(SQUARE), shapely.Polygon(local + s)) for s in shift)
    assert not ov and d == pytest.approx(1.0, abs=1e-9) and sampled > 1.0 + 1e-3


# (c) no coning: FCL is the 2D clearance ----------------------------------------


def test_d4_fcl_equals_2d(d4):
    phi = np.deg2rad(np.arange(30.0, 61.0, 7.5))
    c = tooth_clearance(d4, phi)
    assert np.all(c.min > 0)
    for p in phi:
        r = tooth_check_document(fcl3d.check_tooth(d4, float(p)))
        assert r["agree"] and not r["fcl_overlap"] and r["bound_um"] == 0.0
        # unrounded: the nearest rigid tooth straight from the solids
        rot, shift = d4.pose(np.array([p]))
        flex = fcl3d.flex_tooth_solid(d4, float(p))
        for j in r["rigid_teeth"]:
            d, ov = fcl3d.fcl_distance(flex, fcl3d.rigid_tooth_solid(d4, j))
            c2 = float(d4.clearance_to(rot, shift, np.array([j]))[0])
            assert not ov and abs(d - c2) <= 1e-6
    # the engine's figure is the minimum over the teeth checked
    r = tooth_check_document(fcl3d.check_tooth(d4, float(phi[0])))
    assert r["clearance_2d_um"] == pytest.approx(1e3 * c.min[0], abs=1e-6)


def test_d4_penetration_is_an_overlap(d4):
    # the tooth on the major axis pushed 0.15 mm radially outward, into the rigid teeth
    bw = d4.drive.design.drive.face_width
    rot, shift = d4.pose(np.array([0.0]))
    deeper = d4.flex_local + [0.15, 0.0]
    poly = shapely.Polygon(transform(deeper, rot, shift)[0])
    flex = fcl3d.loft(deeper, np.repeat(rot, 2), np.repeat(shift, 2, axis=0), np.array([0.0, bw]))
    hits = 0
    for j in np.concatenate(d4.neighbours(shift, rot)):
        c2 = shapely.distance(poly, d4.rigid_geoms[j])
        d, ov = fcl3d.fcl_distance(flex, fcl3d.rigid_tooth_solid(d4, int(j)))
        assert ov == (c2 == 0.0)
        assert d == pytest.approx(c2, abs=1e-9)
        hits += ov
    assert hits >= 1


# (d) coning: FCL within the stated bound below the 2D minimum over the sections ----


def test_d1_fcl_within_bound(d1):
    phis = np.deg2rad([-60.0, -40.0, 30.0, 45.0, 60.0])
    bounds = {}
    for n in (9, 17):
        zs = np.linspace(0.0, d1.drive.design.drive.face_width, n)
        for p in phis:
            assert min(tooth_clearance(d1, np.array([p]), float(z)).min[0] for z in zs) > 0
            r = tooth_check_document(fcl3d.check_tooth(d1, float(p), n_sections=n))
            assert r["agree"] and not r["fcl_overlap"]
            d, c2, b = r["fcl_distance_um"], r["clearance_2d_um"], r["bound_um"]
            assert c2 - b - 1e-3 <= d <= c2 + 1e-3
            # the tight check: the 2D section through FCL's nearest point
            assert abs(d - r["clearance_2d_at_witness_um"]) <= r["loft_error_um"] + 1e-3
            for t in r["per_tooth"]:
                assert t["agree"] and t["fcl_distance_um"] <= t["clearance_2d_um"] + 1e-3
                assert t["fcl_distance_um"] >= t["clearance_2d_um"] - t["bound_um"] - 1e-3
            bounds[n, float(p)] = (b, r["loft_error_um"])
    for p in phis:
        (b9, e9), (b17, e17) = bounds[9, float(p)], bounds[17, float(p)]
        assert b17 < b9 and e17 < e9
        assert b17 < 0.6 * b9 + 1e-3  # the dip term is O(h)


def test_d1_loft_error_orders(d1):
    bw = d1.drive.design.drive.face_width
    e9 = fcl3d.loft_error(d1, np.deg2rad(45.0), np.linspace(0.0, bw, 9))
    e17 = fcl3d.loft_error(d1, np.deg2rad(45.0), np.linspace(0.0, bw, 17))
    assert e17["chord"].max() == pytest.approx(e9["chord"].max() / 4, rel=0.05)  # h^2
    assert e17["twist"].max() == pytest.approx(e9["twist"].max() / 2, rel=0.05)  # h
    assert e9["chord"].max() < 1e-6 and e9["twist"].max() < 1e-3
    # the vertex speed along z is what coning gives: the neutral-line point moves by
    # (w, v) dW0/dz / W0 per mm, dW0/dz = W0 / (l - z_h); the tooth turning changes it by a few %
    g = d1.drive.design.generator
    st = d1.drive.law.state(np.deg2rad(45.0))
    v_line = float(np.hypot(st.w, st.v)) / (g.cone_length - g.generator_z)
    assert 0.9 * v_line < e9["speed"].max() < 1.1 * v_line


# (e) the audit's pairs -----------------------------------------------------------


@pytest.mark.parametrize("name", ["d4_discrete", "d1_involute", "d1_involute_nominal"])
def test_verify_worst_agrees(name):
    drive, result = run_audit(TEMPLATES / f"{name}.toml", RunSettings(step_deg=1.0))
    out = check3d_document(fcl3d.verify_worst(drive, result))
    # the pinch is checked where the audit finds one (D1 rebuilt: none - its gaps fall from the tip crossing
    # straight into flank engagement; D4 and the nominal teeth pinch as the tips pass)
    has_pinch = audit_json(result)["entry"]["pinch_um"] is not None
    assert [p["what"] for p in out["pairs"]] == ["tightest"] + (["entry pinch"] if has_pinch else [])
    assert has_pinch == (name != "d1_involute")
    assert out["agree"] and all(p["agree"] for p in out["pairs"])
    assert out["summary"].startswith("agree") and "\n" not in out["summary"]
    w = out["pairs"][0]
    assert w["tooth_angle_deg"] == pytest.approx(audit_json(result)["worst"]["tooth_angle_deg"])
    # the loft's sections include the audit's; the 2D check is on polygons, the audit's figure on the
    # exact curves: they differ by at most the polygon-curve difference (2 x the chord tolerance)
    assert (
        w["clearance_2d_um"]
        <= audit_json(result)["worst"]["clearance_um"] + 2.0 * 1e3 * result.settings.chord_tol + 1e-2
    )
    if result.min_clearance < 0:
        assert w["fcl_overlap"]
    else:
        assert abs(w["fcl_distance_um"] - w["clearance_2d_um"]) <= 1e-3
    json.dumps(out)


@pytest.mark.parametrize(
    "name, errors",
    [
        # D4 (prisms) is apart by 1.8 um: half a micrometre of rigid eccentricity keeps it apart
        ("d4_discrete", (("rigid_eccentricity_um", "0.5"), ("rigid_eccentricity_phase_deg", "30.0"))),
        # D1 (coned) interferes at the tips far from the major axis; errors of [S4]'s order move it by ~10 um
        (
            "d1_involute",
            (
                ("rigid_eccentricity_um", "15.0"),
                ("rigid_eccentricity_phase_deg", "40.0"),
                ("cam_offset_fixed_um", "10.0"),
                ("flex_runout_um", "20.0"),
            ),
        ),
    ],
)
def test_verify_worst_places_the_imperfect_parts(name, errors, tmp_path):
    # the 3D check of an imperfect audit builds the tooth the audit names (its tooth at its generator
    # angle, with the errors) and the rigid teeth with theirs: its 2D figure at the audit's section is the
    # audit's own polygon figure, while the perfect drive's tooth at the same tooth angle is elsewhere
    from conftest import edit_toml

    from wgcad.placement.imperfect import Imperfections, flex_poses, rigid_poses

    text = (TEMPLATES / f"{name}.toml").read_text() + "\n[imperfections]\n"
    for key, val in errors:
        text = edit_toml(text, "imperfections", key, val)
    p = tmp_path / f"{name}_imp.toml"
    p.write_text(text)
    drive, result = run_audit(p, RunSettings(step_deg=1.0))
    imp = Imperfections.from_spec(drive.design.imperfections)
    w = result.findings["min_clearance"]
    out = check3d_document(fcl3d.verify_worst(drive, result, imp=imp))
    assert out["agree"] and out["summary"].startswith("agree")
    pair = out["pairs"][0]
    assert pair["tooth"] == w.tooth and pair["generator_angle_deg"] == pytest.approx(np.rad2deg(w.generator_angle))
    rows = {r["rigid_tooth"]: r for r in pair["per_tooth"]}
    j = w.details["rigid_tooth"]
    # the reference: the two posed polygons from the drive's own poses (placement.imperfect, no scene), in shapely
    rot, shift = flex_poses(
        drive, imp, w.generator_angle, teeth=np.array([w.tooth]), z=w.section_z if drive.coned else None
    )
    rr, rs = rigid_poses(drive, imp, teeth=np.array([j]))
    a = shapely.Polygon(transform(drive.flex.tooth_polygon(), rot, shift)[0])
    b = shapely.Polygon(transform(drive.rigid.tooth_polygon(), rr, rs)[0])
    if a.intersects(b):
        assert rows[j]["fcl_overlap"] and rows[j]["clearance_2d_um"] < 0
    else:
        ref_um = 1e3 * a.distance(b)
        # the loft's sections include the audit's: their minimum is at most that section's (1e-6 um: transforms)
        assert rows[j]["clearance_2d_um"] <= ref_um + 1e-6
        if not drive.coned:
            assert rows[j]["clearance_2d_um"] == pytest.approx(ref_um, abs=1e-6)
            # prisms: the 3D distance is the 2D one (FCL_TOL)
            assert rows[j]["fcl_distance_um"] == pytest.approx(ref_um, abs=1e3 * fcl3d.FCL_TOL)
    # the solid itself: its slice at the audit's section is the tooth placed with its errors (in the frame of
    # the rigid gear's centre, where the imperfect scene holds the rigid teeth)
    from wgcad.clearance.imperfect import ImperfectScene
    from wgcad.placement.imperfect import rigid_translation

    isc = ImperfectScene.from_scene(Scene(drive), imp)
    z_w = w.section_z if drive.coned else 0.0
    zs = np.unique([0.0, z_w, float(drive.design.drive.face_width)])
    V, _ = fcl3d.flex_tooth_solid(
        isc, 0.0, sections=zs, track=fcl3d.imperfect_track(drive, imp, w.generator_angle, w.tooth)
    )
    slice_ = V[np.abs(V[:, 2] - z_w) < 1e-12, :2]
    ref = transform(drive.flex.tooth_polygon(), rot, shift)[0] - rigid_translation(imp)
    gap = np.hypot(*(ref[:, None, :] - slice_[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert gap.max() < 1e-9
    perfect = check3d_document(fcl3d.verify_worst(drive, result))["pairs"][0]
    assert abs(perfect["clearance_2d_um"] - pair["clearance_2d_um"]) > 0.2  # the errors moved the pair
    json.dumps(out)


def test_core_does_not_import_fcl():
    code = (
        "import sys, wgcad.clearance.engine, wgcad.audit, wgcad.clearance;"
        "bad = [m for m in ('fcl', 'manifold3d', 'trimesh') if m in sys.modules]; print(bad); sys.exit(bool(bad))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
