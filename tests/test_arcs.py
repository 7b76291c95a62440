"""Tests of wgcad.export.formats.arcs: biarcs within the chord tolerance of the exact tooth curves (sampled along the arcs), tangent where the curve is smooth, closed and simple, and their DXF round trip."""

import glob
import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import shapely

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.export.formats.arcs import (
    arc_deviation,
    arc_points,
    bulge_centres,
    fit_gear,
    fit_pieces,
    path_area,
    segment_tangents,
)
from wgcad.export.formats.dxf import DxfLayer, audit_dxf, read_dxf, write_dxf
from wgcad.profiles import pieces as pc

TEMPLATES = sorted(glob.glob(str(Path(__file__).parent.parent / "templates" / "*.toml")))
TOL = 1e-3  # mm, the default chord tolerance the arcs are fitted to

# Tangency: where the exact curve is smooth, consecutive arcs share the
# curve's tangent, which the fitter imposes at every split point. The
# written tangents are recomputed from vertices and bulges in float64:
# measured <= 2e-7 rad on every template (short arcs near the tip lose
# digits in the chord direction); 1e-5 rad still fails a fitter that
# ignored tangents (its kinks are of order tol / segment length ~ 1e-2).
TANGENT_TOL = 1e-5  # rad


@pytest.fixture(scope="module", params=[Path(t).stem for t in TEMPLATES])
def drive(request):
    return build_drive(load_design(Path(__file__).parent.parent / "templates" / f"{request.param}.toml"), tol=TOL)


def corner_angles(pieces):
    """Angle between the exact curve's tangents at each piece join (end of piece i -> start of i+1), rad."""
    out = []
    for i, p in enumerate(pieces):
        q = pieces[(i + 1) % len(pieces)]
        # derivatives at the ends themselves: every piece's parameter has a non-zero speed there
        # (cycloids run on u = 1 - cos(phi/2), whose speed is constant through the pitch-point cusp,
        # where the tangent turns fast: a point inside the piece would not do)
        a = p.deriv(np.array([p.t1])) * np.sign(p.t1 - p.t0)
        b = q.deriv(np.array([q.t0])) * np.sign(q.t1 - q.t0)
        a, b = a[0] / np.hypot(*a[0]), b[0] / np.hypot(*b[0])
        out.append(math.acos(max(-1.0, min(1.0, float(a @ b)))))
    return np.array(out)


@pytest.mark.parametrize("which", ["flex", "rigid"])
def test_arcs_within_chord_tolerance_of_the_exact_curve(drive, which):
    gear = getattr(drive, which)
    path = fit_gear(gear, TOL)
    # every written segment sampled, each sample's foot on the exact curve found by Newton: one pitch
    # densely (128 points per arc), all teeth (rotated copies of it) at 12 points per arc
    pieces = list(gear.pieces)
    assert arc_deviation(fit_pieces(pieces, TOL, closed=False), pieces, n_per_arc=128).max() <= TOL
    dev = arc_deviation(path, pieces, n_per_arc=12)
    assert dev.max() <= TOL
    # far fewer entities than the polyline of the same tolerance
    assert len(path.bulges) < 0.8 * len(gear.outline)
    # independent: every polyline vertex (exact points of the curve) lies within tol of the arcs, each arc
    # drawn as a 9-vertex line string (its chords lie inside the arc by at most the sagitta below)
    k = 8
    lines = shapely.linestrings(arc_points(path.vertices, path.ends, path.bulges, k + 1))
    _, d = shapely.STRtree(lines).query_nearest(shapely.points(gear.outline), return_distance=True)
    _, radius, theta = bulge_centres(path.vertices, path.ends, path.bulges)
    with np.errstate(invalid="ignore"):  # straight segments: infinite radius, no sagitta
        sagitta = np.where(np.isfinite(radius), radius * (1 - np.cos(theta / (2 * k))), 0.0).max()
    assert d.max() <= TOL + sagitta


@pytest.mark.parametrize("which", ["flex", "rigid"])
def test_arcs_are_tangent_where_the_curve_is_smooth(drive, which):
    gear = getattr(drive, which)
    pieces = list(gear.pieces)
    one = fit_pieces(pieces, TOL, closed=False)
    ts, te = segment_tangents(one)
    kink = np.arccos(np.clip(np.einsum("ij,ij->i", te[:-1], ts[1:]), -1.0, 1.0))
    src = one.source[:, 0].astype(int)
    piece_join = src[:-1] != src[1:]
    corners = corner_angles(pieces)
    # inside a piece: tangent
    assert kink[~piece_join].max(initial=0.0) <= TANGENT_TOL
    # at a piece join: the arcs turn by exactly the exact curve's corner angle (0 where pieces are tangent)
    assert np.allclose(kink[piece_join], corners[src[:-1][piece_join]], atol=TANGENT_TOL)


@pytest.mark.parametrize("which", ["flex", "rigid"])
def test_arc_outline_is_closed_simple_and_encloses_the_gear_area(drive, which, tmp_path):
    gear = getattr(drive, which)
    path = fit_gear(gear, TOL)
    write_dxf(tmp_path / "g.dxf", [DxfLayer("G", paths=(path,))])
    assert audit_dxf(tmp_path / "g.dxf") == 0
    ((v, b),) = read_dxf(tmp_path / "g.dxf")["G"]["paths"]
    assert np.array_equal(v, path.vertices) and np.array_equal(b, path.bulges)  # exact text round trip
    ring = shapely.LinearRing(arc_points(v, np.roll(v, -1, axis=0), b, 16)[:, :-1].reshape(-1, 2))
    assert ring.is_simple
    steps = np.hypot(*(np.roll(v, -1, axis=0) - v).T)
    assert steps.min() > 1e-6  # no zero-length segments (1 nm, far above CAD programs' 1e-10 point tolerance)
    # area: exact arc-path area against the polyline's; they differ by the chord error times the perimeter at most
    perimeter = float(np.sum(steps)) * 1.1
    assert abs(path_area(v, b) - gear.area()) <= TOL * perimeter


def involute_piece():
    return pc.involute(0.1, 40.0, 0.05, 0.6)


@pytest.mark.parametrize(
    "make",
    [
        involute_piece,
        lambda: pc.cycloid("epicycloid", 40.0, 0.2, 0.0, 3.0),  # starts in a cusp (zero first derivative)
        lambda: pc.cycloid("hypocycloid", 40.0, 0.2, 3.0, 0.0),  # ends in one
    ],
)
@pytest.mark.parametrize("tol", [1e-3, 1e-4, 1e-5])
def test_single_curves_at_several_tolerances(make, tol):
    piece = make()
    path = fit_pieces([piece], tol, closed=False)
    dev = arc_deviation(path, [piece], n_per_arc=256)
    assert dev.max() <= tol
    assert np.allclose(path.vertices[0], piece.start, atol=1e-12)
    assert np.allclose(path.ends[-1], piece.end, atol=1e-12)


def test_deviation_check_catches_a_wrong_arc():
    piece = involute_piece()
    path = fit_pieces([piece], 1e-4, closed=False)
    bad = path.bulges.copy()
    k = len(bad) // 2
    chord = np.hypot(*(path.ends[k] - path.vertices[k]))
    bad[k] += 4e-4 / chord  # the sagitta (bulge * chord / 2) grows by 2e-4 mm: the arc bows out by twice the tolerance
    wrong = type(path)(path.vertices, bad, path.source, path.end)
    assert arc_deviation(wrong, [piece]).max() > 1e-4


def test_exact_arcs_and_lines_are_copied():
    circle = pc.arc((1.0, 2.0), 5.0, 0.0, 2 * np.pi)
    path = fit_pieces([circle], 1e-3)
    assert len(path.bulges) == 2  # two half circles, bulge 1 each
    assert np.allclose(path.bulges, 1.0)
    assert path_area(path) == pytest.approx(np.pi * 25.0, rel=1e-14)
    square = [pc.line((0, 0), (1, 0)), pc.line((1, 0), (1, 1)), pc.line((1, 1), (0, 1)), pc.line((0, 1), (0, 0))]
    sq = fit_pieces(square, 1e-3)
    assert np.all(sq.bulges == 0) and path_area(sq) == 1.0


@pytest.mark.skipif(shutil.which("librecad") is None, reason="LibreCAD not installed")
def test_librecad_reads_the_arc_dxf(tmp_path):
    """A real CAD program opens an arc-path gear DXF with its gear-data text and draws it (optional)."""
    drive = build_drive(load_design(Path(__file__).parent.parent / "templates" / "d4_discrete.toml"), tol=TOL)
    path = tmp_path / "rigid.dxf"
    write_dxf(
        path,
        [
            DxfLayer("RIGID", paths=(fit_gear(drive.rigid, TOL),), circles=((0, 0, drive.rigid_rim_radius),)),
            DxfLayer("GEAR_DATA", texts=((25.0, 20.0, 0.8, "RIGID GEAR DATA"),)),
        ],
    )
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    subprocess.run(
        ["librecad", "dxf2pdf", "-a", "-m", str(path)],
        cwd=tmp_path,
        env=env,
        check=True,
        capture_output=True,
        timeout=120,
    )
    pdf = tmp_path / "rigid.pdf"
    assert pdf.exists() and pdf.stat().st_size > 10_000  # 88 teeth of arcs drawn, not an empty page
    if shutil.which("pdftoppm"):  # LibreCAD draws text as strokes: look at the pixels instead
        subprocess.run(["pdftoppm", "-gray", "-r", "40", str(pdf), str(tmp_path / "page")], check=True, timeout=60)
        import matplotlib.image as mpimg

        img = mpimg.imread(
            next(tmp_path.glob("page*.pgm")) if list(tmp_path.glob("page*.pgm")) else next(tmp_path.glob("page*"))
        )
        assert np.mean(np.asarray(img) < 0.5 * np.max(img)) > 0.005  # lines drawn on the page
