"""The conjugate gear's fast paths against their references (docs/models.md 13.3, 5).

The envelope is taken over many positions in one call: each root is refined
on its own, so the batch equals the envelope taken one position at a time,
bit for bit. The boundary of the swept region asks a tree of the envelope
points once per placed polygon and projects on only the pieces that can hold
a point's nearest: the reference here tests every position's polygon in turn
and projects on every piece, and the flank must come out the same, bit for
bit, on every design with a conjugate rigid gear (the three templates and D1
cycloidal made conjugate, as benchmarks/envelope.py builds it). The exact
tooth of the clearance engine seeds a spline's projection from its own fine
grid and every other piece from the usual one: its seeds, its spline rows and
its audit figures against the dense grid of every piece at the spline's
count.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES

from wgcad.clearance import exact as exact_mod
from wgcad.clearance.engine import AuditSettings, audit
from wgcad.clearance.exact import ExactTooth
from wgcad.design.files import load_design
from wgcad.drive import build_drive
from wgcad.envelope import LawMotion, envelope, flank_pieces, space

#: every design with a conjugate rigid gear: the templates, and D1 cycloidal made conjugate
CONJUGATE = ["d1_conjugate", "d1_conjugate_modified", "d1_double_arc", "d1_cycloidal"]


def _conjugate_drive(name):
    design = load_design(TEMPLATES / f"{name}.toml")
    if design.rigid.flanks != "conjugate":
        design = dataclasses.replace(design, rigid=dataclasses.replace(design.rigid, flanks="conjugate"))
    return build_drive(design)


def _fields(e):
    """The envelope's arrays in the order (t, piece, s)."""
    o = np.lexsort((e.s, e.piece, e.t))
    return {f: getattr(e, f)[o] for f in ("t", "piece", "s", "points", "normal", "branch", "residual_mm")}


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal", "d1_double_arc"])
def test_the_envelope_of_many_positions_is_the_envelope_of_each_position(name):
    """401 positions over the pass in one call against one call per position: every field equal bit for bit (a
    Newton iteration that ran every root until the slowest converged gave each root a last step that hung on its
    batch)."""
    d = build_drive(load_design(TEMPLATES / f"{name}.toml"))
    mot = LawMotion(d.law, d.r_m, d.design.drive.z_flex, d.design.drive.z_rigid)
    pieces = flank_pieces(d.flex, +1)
    t = np.linspace(-1.4, 1.4, 401)
    batch = _fields(envelope(pieces, mot, t))
    one = [envelope(pieces, mot, [tk]) for tk in t]
    ref = {f: np.concatenate([getattr(e, f) for e in one]) for f in batch}
    ref = _fields(type(one[0])(**ref))
    assert len(batch["t"]) > 100
    for f in batch:
        assert np.array_equal(batch[f], ref[f]), f


def _outside_each_position(x, polys, tol, exact):
    """The reference boundary test: every position's chord polygon in turn covers the points it holds (on its
    boundary included) by their distance from its ring; the closer calls go to the exact test, all of them."""
    ok = np.ones(len(x), dtype=bool)
    ask_i, ask_j = [], []
    for k, poly in enumerate(polys):
        g = shapely.Polygon(poly)
        hit = np.flatnonzero(shapely.intersects_xy(g, x[:, 0], x[:, 1]))
        depth = shapely.distance(g.exterior, shapely.points(x[hit]))
        ok[hit[depth > tol]] = False
        ask_i.append(hit[depth <= tol])
        ask_j.append(np.full(np.sum(depth <= tol), k))
    i, j = np.concatenate(ask_i), np.concatenate(ask_j)
    live = ok[i]
    i, j = i[live], j[live]
    if i.size:
        ok[i[exact(i, j) > -tol]] = False
    return ok


def _exact_every_piece(x, rot, shift, outline, starts):
    """The reference exact side: projected on every piece from its nearest start, the nearest projection's side."""
    c, sn = np.cos(rot)[:, None], np.sin(rot)[:, None]
    best, gap = np.full(len(x), np.inf), np.full(len(x), np.inf)
    for p, sg in zip(outline, starts):
        P = p.point(sg)
        px = P[None, :, 0] * c - P[None, :, 1] * sn + shift[:, None, 0]
        py = P[None, :, 0] * sn + P[None, :, 1] * c + shift[:, None, 1]
        s0 = sg[np.argmin(np.hypot(px - x[:, None, 0], py - x[:, None, 1]), axis=1)]
        d, g = space._side_distance(p, s0, x, rot, shift, with_gap=True)
        closer = g < gap
        best[closer], gap[closer] = d[closer], g[closer]
    return best


@pytest.mark.parametrize("name", CONJUGATE)
def test_the_conjugate_flank_is_the_one_a_position_by_position_test_finds(name, monkeypatch):
    """The conjugate flank (its exact points, angles, normals, residuals and chord sagitta) with the fast boundary
    test against the reference's, bit for bit: the same envelope points are kept."""
    d = _conjugate_drive(name)
    z = d.design.rigid.conjugate_z
    z = (d.design.generator.generator_z if z is None else z) if d.coned else None
    fast = space.conjugate_flank(d, z)
    monkeypatch.setattr(space, "_outside_all", _outside_each_position)
    monkeypatch.setattr(space, "_exact_side", _exact_every_piece)
    ref = space.conjugate_flank(d, z)
    assert len(fast.points) > 50
    for f in ("points", "t", "normal", "residual_mm"):
        assert np.array_equal(getattr(fast, f), getattr(ref, f)), f
    assert fast.sagitta_mm == ref.sagitta_mm


def _points_near(tooth, n, rng):
    """Points within 0.2 mm of the tooth's pieces (where the audit measures), tooth frame."""
    j = rng.integers(0, tooth.n, n)
    t = tooth.lo[j] + rng.random(n) * (tooth.hi[j] - tooth.lo[j])
    P = np.array([tooth.pieces[a].point([b])[0] for a, b in zip(j, t)])
    return P + rng.normal(scale=0.1, size=(n, 2))


@pytest.mark.parametrize("name", ["d1_cycloidal", "d1_involute"])
def test_the_exact_tooths_nearest_seeds_are_the_dense_grids(name):
    """For 3000 points near the tooth, each piece's nearest grid point (a spline's through its tree, the others by
    the matrix product) against every grid point's distance by brute force: the same squared distance to 1e-12
    mm^2 (the matrix product's rounding) and an index at that distance. Both gears of a conjugate drive (the
    rigid one has two splines of thousands of seeds) and of the design's own."""
    rng = np.random.default_rng(3)
    d = _conjugate_drive(name)
    for gear in (d.rigid, d.flex):
        tooth = ExactTooth(gear, gear.tooth_polygon())
        x = _points_near(tooth, 3000, rng)
        d2, arg = tooth.nearest_grid(x)
        for j in range(tooth.n):
            g = tooth.pieces[j].point(tooth.grid_t[j, : tooth.grid_n[j]])
            brute = ((x[:, None, :] - g[None]) ** 2).sum(-1)
            assert np.abs(d2[:, j] - brute.min(axis=1)).max() < 1e-12
            assert np.abs(brute[np.arange(len(x)), arg[:, j]] - brute.min(axis=1)).max() < 1e-12
        assert gear is d.flex or (tooth.grid_n > exact_mod._SEED_GRID).sum() == 2


def test_the_spline_rows_of_the_exact_tooth_are_the_pieces_own():
    """The conjugate flank's rows, evaluated in one call over every segment of both splines (with the arcs and
    lines between), equal each piece's own point and derivatives bit for bit, at the knots and off them."""
    d = _conjugate_drive("d1_cycloidal")
    tooth = ExactTooth(d.rigid, d.rigid.tooth_polygon())
    rng = np.random.default_rng(5)
    idx = rng.integers(0, tooth.n, 20000)
    t = tooth.lo[idx] + rng.random(len(idx)) * (tooth.hi[idx] - tooth.lo[idx])
    spl = np.flatnonzero(np.array([p.kind == "spline" for p in tooth.pieces]))
    knots = np.isin(idx, spl) & (rng.random(len(idx)) < 0.2)
    t[knots] = np.round(t[knots])  # on a knot: the segment boundary and the spline's last point
    P, D1, D2 = tooth.eval(idx, t)
    assert np.isin(idx, spl).sum() > 1000
    for j in range(tooth.n):
        m = idx == j
        p = tooth.pieces[j]
        assert np.array_equal(P[m], p.point(t[m]))
        assert np.array_equal(D1[m], p.deriv(t[m]))
        assert np.array_equal(D2[m], p.deriv2(t[m]))


def _same(a, b) -> bool:
    """Equal figures: floats to 1e-9 relative or 1e-12 (mm, rad), everything else exactly, recursively."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if dataclasses.is_dataclass(a):
        return type(a) is type(b) and all(_same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, (float, np.floating, np.ndarray)):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        both = np.isnan(a) & np.isnan(b)
        return a.shape == b.shape and bool(np.all(both | (np.abs(a - b) <= np.maximum(1e-12, 1e-9 * np.abs(b)))))
    return a == b


def test_the_audit_of_a_conjugate_pair_is_the_one_of_the_dense_grid(monkeypatch):
    """D1's conjugate pair over a generator turn at 2 deg, refined on the exact curves: every figure, where it lies
    and every count of the audit with a spline's own seed grid and the usual one elsewhere equal the ones with
    every piece of the rigid tooth seeded as finely as its splines (one (points, pieces, seeds) array, as the seeds
    were laid out before), to 1e-9 relative or 1e-12 mm (a flat minimum: the contact runs along the whole path,
    so where it lies hangs on the last bit of its figure)."""
    d = _conjugate_drive("d1_conjugate")
    st = AuditSettings(angles=np.deg2rad(np.arange(180) * 2.0), sections=[18.0], interference_tol=1e-3, refine=True)
    fast = audit(d, st)
    init = ExactTooth.__init__

    def dense_init(self, gear, polygon):
        with monkeypatch.context() as m:  # every piece of a tooth with a spline seeded at the spline's count
            n = [4 * (len(p.params) // 8) + 1 for p in gear.pieces if p.kind == "spline"]
            m.setattr(exact_mod, "_SEED_GRID", max([exact_mod._SEED_GRID] + n))
            init(self, gear, polygon)

    monkeypatch.setattr(ExactTooth, "__init__", dense_init)
    ref = audit(d, st)
    assert fast.counts == ref.counts
    assert fast.findings.keys() == ref.findings.keys()
    for key in fast.findings:
        assert _same(fast.findings[key], ref.findings[key]), key
