"""Tooth-root stress concentration of a bent flexspline rim: self-checks of the independent plane-strain FE reference (tests/fe_root_reference.py) and wgcad.rating.notch against it.

Measured with the reference (refine 1 / 2, DOFs at refine 1): d1_involute
kt 2.386 / 2.383 (13 114 DOFs), d1_cycloidal 1.919 / 1.919 (8 452), d2
2.402 / 2.394 (13 406); a plain curved bar (r_m/h1 = 58) gives 0.99434,
the exact curved-bar value 0.99427 (Winkler correction -0.57 %). The whole
file runs in about 4 s.
"""

import functools
import sys
from pathlib import Path

import numpy as np
import pytest

from wgcad.design.files import load_design
from wgcad.drive import build_drive

sys.path.insert(0, str(Path(__file__).parent))
from fe_root_reference import curved_bar_kt, reference_root_kt  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES = ["d1_involute", "d1_cycloidal", "d2"]


@functools.cache
def _drive(name):
    return build_drive(load_design(ROOT / "templates" / f"{name}.toml"))


@functools.cache
def _reference(name, refine=1.0, plain=False):
    return reference_root_kt(_drive(name), refine=refine, plain=plain)


def test_plain_bar_gives_unity():
    # the toothed boundary replaced by the root circle: a curved bar of thickness h1 in pure bending;
    # measured 0.99434 against the exact plane-strain curved-bar solution 0.99427 (r_m/h1 = 58)
    d = _drive("d1_involute")
    r = _reference("d1_involute", plain=True)
    exact = curved_bar_kt(d.flex_rim_radius, d.flex.r_f, d.r_m)
    assert abs(exact - 1.0) < 0.01  # the Winkler correction, -0.57 % here
    assert abs(r["kt"] - 1.0) < 0.01
    assert abs(r["kt"] - exact) < 1e-3
    assert abs(r["radius"] - d.flex.r_f) < 1e-9  # the surface of the middle pitch
    assert abs(r["kt_left"] - r["kt_right"]) < 1e-3


def test_refinement_converges():
    # every mesh size halved (about 2.2x the DOFs): measured change 0.13 % (2.3857 -> 2.3827)
    coarse, fine = _reference("d1_involute"), _reference("d1_involute", refine=2.0)
    assert fine["dofs"] > 2 * coarse["dofs"]
    assert abs(fine["kt"] / coarse["kt"] - 1.0) < 0.02


@pytest.mark.parametrize("name", TEMPLATES)
def test_peak_sits_at_the_root_symmetrically(name):
    g = _drive(name).flex
    r = _reference(name)
    tooth_h = g.r_a - g.r_f
    assert 1.5 < r["kt"] < 3.5
    # on the root region, both sides of the middle tooth alike
    assert g.r_f - 1e-6 <= r["radius"] < g.r_f + 0.25 * tooth_h
    assert 0.5 * np.pi / g.spec.z < abs(r["angle"]) <= np.pi / g.spec.z
    assert abs(r["kt_left"] / r["kt_right"] - 1.0) < 0.01


@pytest.mark.parametrize("name", TEMPLATES)
def test_core_matches_the_reference(name):
    """Issue 24 asks for 15 %; the core's linear triangles at their default mesh measured within 1.8 % of the
    converged quadratic reference (d1_involute -0.1 %, d1_cycloidal +1.8 %, d2 -0.7 %), so 5 % is held: room for
    the two meshes' placement, not for a wrong peak (the polyline outline with the coarser first mesh gave +12 %)."""
    from wgcad.rating import notch

    d = _drive(name)
    kt = notch.root_concentration(d.flex, d.flex_rim_radius).kt
    ref = _reference(name)["kt"]
    assert abs(kt / ref - 1.0) < 0.05, f"{name}: core kt {kt:.4f}, reference {ref:.4f}"


def test_a_solved_geometry_is_answered_from_memory_and_any_change_of_it_is_solved_again(monkeypatch):
    """The FE runs once per geometry: the same flexspline asked twice (a datasheet with a cam offset rates its
    drive twice) is one solve; a generator's amplitude, which moves no tooth, is none; a fillet, a thinned tooth,
    a thinner rim (the bore) each change the digest, are solved again, and give their own K (not the first one's)."""
    from wgcad.design.schema import with_changes
    from wgcad.rating import notch

    calls = []
    real = notch._root_concentration
    monkeypatch.setattr(notch, "_SOLVED", {})
    monkeypatch.setattr(notch, "_root_concentration", lambda *a: calls.append(a) or real(*a))
    base = load_design(ROOT / "templates" / "d1_involute.toml")

    def kt(design):
        d = build_drive(design)
        return notch.root_concentration(d.flex, d.flex_rim_radius)

    first = kt(base)
    assert kt(base) is first and len(calls) == 1
    assert kt(with_changes(base, generator={"w0_coef": 0.95})) is first and len(calls) == 1
    changed = [
        with_changes(base, flexspline={"fillet_coef": base.flexspline.fillet_coef * 1.5}),
        with_changes(base, flexspline={"thinning": 0.04}),
        with_changes(base, flexspline={"rim_thickness": base.flexspline.rim_thickness * 0.9}),
    ]
    for n, d in enumerate(changed, start=2):
        k = kt(d)
        assert len(calls) == n and k is not first
        fresh = real(build_drive(d).flex, build_drive(d).flex_rim_radius, 5, 2.0, 206e3, 0.3)
        assert k == fresh
