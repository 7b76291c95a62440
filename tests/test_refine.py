"""The refinement on the exact curves against independent dense polygons, pair by pair (docs/models.md 5).

:func:`wgcad.clearance.refine.refine_pairs` claims the signed clearance of
two placed teeth on their exact curves to :data:`wgcad.constants.REFINE_TOL`
(0.001 um). The reference here does not use the refinement: the same teeth
sampled at 0.0001 um chords (their polygons lie within 1e-7 mm of the
curves, so a polygon figure is within 2e-7 mm of the exact one) and measured
with shapely (distance when apart; when overlapping, the deepest vertex of
either outline inside the other, measured to the other's outline). Pairs
are taken where the teeth are within 50 um of touching or overlap, on
every bundled tooth form and deformation kind.
"""

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES
from test_exact import dense_pair  # the same shapely reference as the audit-level test

from wgcad.clearance.distance import Template
from wgcad.clearance.scene import Scene, clearance_at_poses
from wgcad.constants import REFINE_TOL
from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.placement import transform

#: the dense polygons' own error: 2 x their chord tolerance (one per tooth)
DENSE_TOL = 1e-7


def _pairs(name, n_pairs=12):
    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    scene = Scene(drive)
    z = None if not drive.coned else float(drive.sections(3)[0])  # the open end (z = 0): the deepest engagement
    half = np.pi / scene.n_w
    phi = np.linspace(-half, half, 1441)
    rot, shift = scene.pose(phi, z)
    det = clearance_at_poses(scene, rot, shift)
    rows, idx = [], []
    for val, rigid in ((det.lower, det.lo), (det.upper, det.up)):
        sel = np.nonzero(val < 0.05)[0]
        pick = sel[np.linspace(0, len(sel) - 1, min(n_pairs // 2, len(sel))).astype(int)] if sel.size else sel
        # and the pairs nearest to grazing contact (|clearance| smallest), where the value is flattest
        graze = np.argsort(np.abs(val))[:3]
        pick = np.union1d(pick, graze)
        rows.append(pick)
        idx.append(rigid[pick])
    rows, idx = np.concatenate(rows), np.concatenate(idx)
    return drive, scene, z, rot[rows], shift[rows], idx


#: (template, pairs per flank): D3 at 60 holds a near-conformal grazing pair (flanks of almost equal
#: curvature 2 nm apart over a millimetre) that Newton on the squared distance left 2.2 nm high
CASES = [("d1_involute", 12), ("d1_cycloidal", 12), ("d2", 12), ("d3_external", 60), ("d4_discrete", 12)]


@pytest.mark.parametrize("name,n_pairs", CASES)
def test_refined_pairs_match_dense_polygons(name, n_pairs):
    drive, scene, z, rot, shift, j = _pairs(name, n_pairs)
    assert len(rot) >= 8  # the templates engage: there are pairs to check
    value = scene.exact_to(rot, shift, j)[0]
    dense = build_drive(drive.design, tol=DENSE_TOL / 2)
    fa, fb = dense.flex.tooth_polygon(), dense.rigid.tooth_polygon()
    a = transform(fa, rot, shift)
    b = transform(fb, scene.rigid_rot[j], scene.rigid_shift[j])
    ref = np.array([dense_pair(a[k], b[k]) for k in range(len(rot))])
    # both signs occur among the checked pairs on most templates: apart and overlapping
    assert np.abs(value - ref).max() <= REFINE_TOL + DENSE_TOL, (1e3 * (value - ref)).round(5)


def test_boundary_distance_matches_shapely():
    # the numpy point-to-outline distance used for penetration depths, against GEOS
    drive = build_drive(load_design(TEMPLATES / "d1_cycloidal.toml"))
    t = Template(drive.rigid.tooth_polygon())
    rng = np.random.default_rng(3)
    lo, hi = t.local.min(axis=0), t.local.max(axis=0)
    pts = rng.uniform(lo - 0.2, hi + 0.2, size=(5000, 2))
    ref = shapely.distance(t.ring, shapely.points(pts))
    assert np.abs(t.boundary_distance(pts) - ref).max() < 1e-12


def test_backlash_on_the_exact_curves_matches_dense_polygons_at_any_chord_tolerance():
    # issue 8: backlash is a figure of the summary, so it too must not depend on the chord
    # tolerance. D4 has dead travel at generator angle 0 (0.8 arcmin). The reference is the polygon
    # backlash of 0.00005 um outlines: their clearance is within 1e-7 mm of the curves', which at the
    # contacts' slopes (~19 mm per rad of turn on D4) moves each side's contact by ~5e-9 rad; two
    # sides: tolerance 2e-8 rad (0.004 arcsec). The 1 um polygons alone are 2.6 arcsec short.
    from wgcad.clearance.backlash import backlash

    design = load_design(TEMPLATES / "d4_discrete.toml")
    ref = backlash(Scene(build_drive(design, tol=5e-8)), 0.0, None)
    exact = [backlash(Scene(build_drive(design, tol=t)), 0.0, None, exact=True) for t in (1e-2, 1e-3)]
    poly = backlash(Scene(build_drive(design, tol=1e-3)), 0.0, None)
    assert abs(exact[0] - ref) < 2e-8 and abs(exact[1] - ref) < 2e-8
    assert abs(exact[0] - exact[1]) < 1e-10
    assert abs(poly - ref) > 5e-6  # the polygon figure was off: the test would have caught it


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d2"])
def test_pairs_far_apart_match_dense_polygons(name):
    # Teeth apart are measured from one side only (the other side's minimum is the same distance);
    # the entry's gaps reach a millimetre, and there a flank nearly parallel to the other tooth's flank
    # meets its tip corner: Newton on the first side alone stopped 1.2 um high on D1's non-working
    # crossing gap (639.705 against 638.528 um) until such rows were flagged and the second side measured
    drive = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    scene = Scene(drive)
    z = None if not drive.coned else float(drive.sections(3)[-1])
    half = np.pi / scene.n_w
    phi = np.linspace(-half, half, 721)
    rot, shift = scene.pose(phi, z)
    det = clearance_at_poses(scene, rot, shift)
    rows, idx = [], []
    for val, rigid in ((det.lower, det.lo), (det.upper, det.up)):
        sel = np.nonzero((val > 0.05) & (val < 1.5))[0]
        pick = sel[np.linspace(0, len(sel) - 1, min(10, len(sel))).astype(int)] if sel.size else sel
        rows.append(pick)
        idx.append(rigid[pick])
    rows, j = np.concatenate(rows), np.concatenate(idx)
    assert len(rows) >= 10
    rot, shift = rot[rows], shift[rows]
    value = scene.exact_to(rot, shift, j)[0]
    dense = build_drive(drive.design, tol=DENSE_TOL / 2)
    a = transform(dense.flex.tooth_polygon(), rot, shift)
    b = transform(dense.rigid.tooth_polygon(), scene.rigid_rot[j], scene.rigid_shift[j])
    ref = np.array([dense_pair(a[k], b[k]) for k in range(len(rot))])
    assert np.abs(value - ref).max() <= REFINE_TOL + DENSE_TOL, (1e3 * (value - ref)).round(5)


def test_d1_entry_crossing_gap_of_the_non_working_edge_is_exact():
    # the pair where the first side alone stopped short (above), at the audit's own poses
    from wgcad.clearance.entry import crossings, edge_gaps, section_poses

    drive = build_drive(load_design(TEMPLATES / "d1_involute.toml"))
    scene = Scene(drive)
    z = float(drive.sections(3)[-1])
    poses = section_poses(scene, [z])
    cross = float(crossings(scene, poses, 1)[0])
    phi = cross + np.linspace(-0.02, 0.02, 9)
    rot, shift = poses(phi, np.zeros(len(phi), dtype=int))
    gaps = edge_gaps(scene, rot, shift)
    dense = build_drive(drive.design, tol=DENSE_TOL / 2)
    jw, jn = (lambda lo, up: (up, lo) if scene.working == "upper" else (lo, up))(*scene.neighbours(shift, rot)[:2])
    a = transform(dense.flex.tooth_polygon(), rot, shift)
    for col, j in ((0, jw), (1, jn)):
        b = transform(dense.rigid.tooth_polygon(), scene.rigid_rot[j], scene.rigid_shift[j])
        ref = np.array([dense_pair(a[k], b[k]) for k in range(len(rot))])
        assert np.abs(gaps[:, col] - ref).max() <= REFINE_TOL + DENSE_TOL, (1e3 * (gaps[:, col] - ref)).round(5)


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d2_imperfect"])
def test_the_finer_polygons_prune_pairs_without_changing_the_minimum(name, monkeypatch):
    """A flat minimum's candidates are sorted out on finer polygons, and their exact refinement then takes only the
    pairs within the finer margin of each sample's smallest. Against every candidate refined with every pair within
    the coarse margin (no finer pass: FINE_ABOVE beyond the candidates' count), the audit's minimum is the same to
    the bit and at the same sample."""
    from wgcad.audit import RunSettings, run_audit
    from wgcad.clearance import cascade

    path = TEMPLATES / f"{name}.toml"
    _, pruned = run_audit(path, RunSettings(step_deg=1.0))
    assert pruned.counts["fine_polygon"] > 0  # the finer pass ran
    monkeypatch.setattr(cascade, "FINE_ABOVE", 10**9)
    _, every = run_audit(path, RunSettings(step_deg=1.0))
    assert every.counts["fine_polygon"] == 0 and every.counts["refined"] > pruned.counts["refined"]
    a, b = pruned.findings["min_clearance"], every.findings["min_clearance"]
    assert a.value == b.value and a.tooth_angle == b.tooth_angle and a.section_z == b.section_z


@pytest.mark.parametrize("path", sorted(TEMPLATES.glob("*.toml")), ids=lambda p: p.stem)
def test_exact_backlash_approached_from_apart_equals_newton_on_the_signed_figure(path):
    """The exact dead travel found by turning each tooth towards contact from where it is apart (the batch's
    distance, backlash._approach) equals Newton's method on the exact signed figure from the polygon roots (the
    computation it replaced, backlash._newton_signed), on every template, to 1e-10 rad (measured: 3e-11 on D4
    discrete, below 1e-14 elsewhere); 1e-10 rad is 0.00003 arcsec."""
    from wgcad.clearance import backlash as bl

    drive = build_drive(load_design(path))
    fast = bl.backlash(Scene(drive), 0.0, None, exact=True)
    approach = bl._approach
    try:
        bl._approach = lambda scene, turned, rows, dirs, rigid, start, back: np.full(len(rows), np.nan)
        slow = bl.backlash(Scene(drive), 0.0, None, exact=True)
    finally:
        bl._approach = approach
    if np.isnan(slow):
        assert np.isnan(fast)
    else:
        assert fast == pytest.approx(slow, abs=1e-10)
