"""The loaded model's fast paths against their reference paths (issue 37): the ring's field of many loads by sorted
suffix sums (docs/models.md 4.1) against the kernel matrix it replaces, on random angles and on every template's
solved states; the datasheet's searches, which measure only the figures their criterion reads, against full levels.
"""

from __future__ import annotations

import functools
from math import pi
from pathlib import Path

import numpy as np
import pytest

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
from wgcad.elastic.loaded import LoadedLaw
from wgcad.elastic.ring import Ring

ROOT = Path(__file__).resolve().parent.parent
BEARING_TEMPLATES = ["d1_involute", "d1_cycloidal", "d2", "d2_imperfect"]


def _direct(ring: Ring, phi, psi, loads, order: int):
    """The reference: every kernel at every (point, load) pair, summed (the K x L matrix)."""
    x = np.asarray(phi, float)[:, None] - np.asarray(psi, float)[None, :]
    loads = np.asarray(loads, float).reshape(len(psi), 3)
    d = [np.zeros(len(phi)) for _ in range(order + 3)]
    for j, vf in enumerate(ring._vfields(x, order)):
        for i in range(order + 3):
            d[i] += vf[i] @ loads[:, j]
    return d


def _direct_field(self, phi, psi, loads):
    phi, psi = np.atleast_1d(np.asarray(phi, float)), np.atleast_1d(np.asarray(psi, float))
    v, v1, v2, v3 = _direct(self, phi, psi, loads, 1)
    r = self.r
    return {"w": -v1, "dw": -v2, "d2w": -v3, "v": v, "dv": v1, "theta": (v + v2) / r, "dtheta": (v1 + v3) / r}


def _direct_displacements(self, phi, psi, loads):
    phi, psi = np.atleast_1d(np.asarray(phi, float)), np.atleast_1d(np.asarray(psi, float))
    v, v1, v2 = _direct(self, phi, psi, loads, 0)
    return -v1, v, (v + v2) / self.r


def _close(a, b, rel):
    """``a`` equals ``b`` to ``rel`` of the largest value of either (the fields' own scale)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(float(np.abs(a).max(initial=0.0)), float(np.abs(b).max(initial=0.0)), 1e-300)
    return float(np.abs(a - b).max(initial=0.0)) <= rel * scale


# the sums reorder the kernel's products: measured 7e-13 of the largest value over random loads; 1e-11 leaves
# room for other platforms' rounding and still fails on any dropped term (a term's share is >= 1e-4 of the field)
REL = 1e-11


@pytest.mark.parametrize("seed", range(6))
def test_the_field_by_sorted_sums_equals_the_kernel_matrix(seed):
    rng = np.random.default_rng(seed)
    ring = Ring(float(rng.uniform(20, 120)), float(rng.uniform(1e5, 1e8)))
    K, L = int(rng.integers(1, 60)), int(rng.integers(1, 50))
    phi = rng.uniform(-3 * pi, 3 * pi, K)
    psi = rng.uniform(-3 * pi, 3 * pi, L)
    # points on loads, on loads a turn or two away, and at the turn's ends: where a couple's dtheta jumps
    m = min(K, L)
    phi[: m // 2] = psi[: m // 2] + 2 * pi * rng.integers(-2, 3, m // 2)
    if K > 2:
        phi[-1], phi[-2] = 0.0, 2 * pi
    loads = rng.normal(size=(L, 3)) * [1.0, 1.0, 30.0]
    got = ring.field(phi, psi, loads)
    want = _direct_field(ring, phi, psi, loads)
    for k in want:
        assert _close(got[k], want[k], REL), k
    for a, b in zip(ring.displacements(phi, psi, loads), _direct_displacements(ring, phi, psi, loads)):
        assert _close(a, b, REL)


def test_a_dropped_term_or_a_wrong_branch_is_seen():
    """The comparison above can fail: the fast sums with one table entry changed, or without the branch
    correction on points that sit on couples, differ from the kernel matrix by far more than ``REL``."""
    import wgcad.elastic.ring as ring_mod

    rng = np.random.default_rng(3)
    ring = Ring(60.0, 1e6)
    psi = rng.uniform(0, 2 * pi, 20)
    phi = np.concatenate([psi + 2 * pi, rng.uniform(0, 2 * pi, 30)])
    loads = rng.normal(size=(20, 3)) * [1.0, 1.0, 30.0]
    want = _direct_field(ring, phi, psi, loads)
    coef, split = ring_mod._TABLES[4]
    broken = coef.copy()
    b = int(np.argmax(np.abs(coef[1, 0])))  # the largest term of the radial load's v' (so of w)
    broken[1, 0, b] *= 1.0 + 1e-6
    ring_mod._TABLES[4] = (broken, split)
    try:
        got = ring.field(phi, psi, loads)
    finally:
        ring_mod._TABLES[4] = (coef, split)
    assert not _close(got["w"], want["w"], REL)
    saved = ring_mod._same_branch
    ring_mod._same_branch = lambda *a: None
    try:
        got = ring.field(phi, psi, loads)
    finally:
        ring_mod._same_branch = saved
    assert not _close(got["dtheta"], want["dtheta"], REL)


@functools.cache
def _model(name):
    return build_model(build_drive(load_design(ROOT / "templates" / f"{name}.toml")))


def _torques(name):
    """Three torques from light to near D1's rated range, scaled with the drive's size (D1: 100, 400, 1000 N m)."""
    r = _model(name).drive.r_m / 80.0
    return [t * r**3 for t in (100.0, 400.0, 1000.0)]


@pytest.mark.parametrize("name", BEARING_TEMPLATES)
def test_every_templates_loaded_rim_is_the_kernel_matrixs(name):
    """The solved states' rims (every section and both waves, at the contacts' own angles and a fine grid) by the
    fast field equal the kernel matrix's, at three torques."""
    model = _model(name)
    warm = None
    for T in _torques(name):
        st = solve_load(model, T, warm=warm)
        warm = st
        laws = [law for law in st.laws if isinstance(law, LoadedLaw)]
        assert laws
        phi = np.concatenate([np.linspace(0, 2 * pi, 1440, endpoint=False), st.contacts["phi"]])
        for law in laws:
            for p in (phi, phi + pi):
                got = law.ring.field(p, law.psi, law.loads)
                want = _direct_field(law.ring, p, law.psi, law.loads)
                for k in want:
                    assert _close(got[k], want[k], REL), (T, k)


@pytest.mark.parametrize("name", ["d1_involute", "d2_imperfect"])
def test_states_and_the_loaded_ke_are_the_reference_paths(name, monkeypatch):
    """The whole solve on the fast field against the whole solve on the kernel matrix: the same forces and
    rotations at three torques, and d2_imperfect's loaded KE at ten generator angles (whole mesh periods)."""
    from wgcad.accuracy.ke_load import loaded_ke
    from wgcad.placement.imperfect import Imperfections

    model = _model(name)
    torques = _torques(name)

    def run():
        out = [solve_load(model, T) for T in torques]
        ke = None
        if name == "d2_imperfect":
            imp = Imperfections.from_spec(model.drive.design.imperfections)
            ke = loaded_ke(model.drive, imp, torques[1], samples=10, model=model, workers=1)
        return out, ke

    fast, ke_fast = run()
    monkeypatch.setattr(Ring, "field", _direct_field)
    monkeypatch.setattr(Ring, "displacements", _direct_displacements)
    ref, ke_ref = run()
    for a, b in zip(fast, ref):
        assert _close(a.contacts["force"], b.contacts["force"], 1e-9)
        assert a.wind_up == pytest.approx(b.wind_up, rel=1e-9, abs=1e-15)
    if ke_fast is not None:
        assert len(ke_fast.periods) == 10
        assert np.array_equal(ke_fast.periods, ke_ref.periods)
        assert _close(ke_fast.theta, ke_ref.theta, 1e-9)
        assert _close(ke_fast.ke, ke_ref.ke, 1e-9)


def test_a_search_level_holds_the_figures_of_a_full_level():
    """A level solved for one criterion's search holds that criterion's figures, equal to a full level's, and its
    margins name only them."""
    from wgcad.rating import datasheet as D

    drive = build_drive(load_design(ROOT / "templates" / "d1_involute.toml"))
    ctx, _ = D._context(drive, 3, drive.design.load.input_speed_rpm)
    ld = drive.design.load
    full = D._level(ctx, 400.0, None, (0.0, 0.0))
    assert set(full.margins(ld)) == {"fatigue", "yield", "bearing_life", "entry_gap"}
    for need, names in (
        ({"stresses"}, {"fatigue", "yield"}),
        ({"life"}, {"bearing_life"}),
        ({"entry_gap"}, {"entry_gap"}),
        ({"depth"}, set()),
    ):
        part = D._level(ctx, 400.0, None, (0.0, 0.0), need)
        m = part.margins(ld)
        assert set(m) == names
        for k in names:
            assert m[k] == pytest.approx(full.margins(ld)[k], rel=1e-12, abs=1e-15)
        if "depth" in need:
            assert np.array_equal(part.depth, full.depth)
        else:
            assert part.depth is None


@pytest.mark.parametrize("name", ["d1_involute", "d1_cycloidal"])
def test_one_edge_measured_alone_is_the_two_edge_measurement(name):
    """The entry refinement measures only the edge each of its jobs follows: the same figures, exact and on the
    outlines, as measuring both edges and reading one, at poses through a tooth's entry."""
    from wgcad.clearance.entry import edge_gaps, section_poses

    scene = _model(name).scene
    poses = section_poses(scene, [0.0])
    phi = np.linspace(0.02, 0.2, 12) * scene.entry_sign
    rot, shift = poses(phi, np.zeros(len(phi), dtype=int))
    e = np.arange(len(phi)) % 2
    for exact in (True, False):
        both = edge_gaps(scene, rot, shift, exact=exact)
        one = edge_gaps(scene, rot, shift, exact=exact, edges=e)
        np.testing.assert_array_equal(one, both[np.arange(len(phi)), e])
