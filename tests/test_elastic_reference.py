"""The fast elastic solver against a plain one (tests/elastic_plain.py), on the source drives (docs/models.md 4.1).

The plain solver evaluates the ring from its kernels at every pass, measures every
tooth pair near engagement on the exact geometry at every pass, solves a dense
system with the supports folded in, and iterates plainly; the fast one reads the
ring from tables, measures again only pairs that can be closing, accelerates the
iteration and warm-starts. They must reach the same fixed point. Both are asked
to stop within 0.05 um of rim motion per pass (the fast one at POSITION_TOL / 4),
so the tolerances are set from that step:

- rim positions (w, v of every section at the tooth angles): within POSITION_TOL / 2
  (each within one step of the fixed point);
- rim rotation: within POSITION_TOL / (2 r_m);
- forces: a tooth pair's stiffness along the normal is 1-2e5 N/mm (bending and
  Hertz over a section's width), so a 0.05 um step moves a force by up to ~10 N,
  with the largest forces 1.5-6 kN: per-tooth and per-ball forces within 1 % of
  the largest.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
from wgcad.elastic.state import POSITION_TOL

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from elastic_plain import plain_solve  # noqa: E402

_MODELS = {}
CASES = [
    ("d1_involute", 0.0, 0.0),
    ("d1_involute", 1000.0, 0.0),
    ("d1_involute", 3000.0, 0.0),
    ("d1_involute", 1000.0, 40.0),
    pytest.param(
        "d1_cycloidal",
        1500.0,
        0.0,
        marks=pytest.mark.xfail(
            strict=True,
            reason="known limit: on this conformal contact the plain fixed point stalls at 1.2e-4 mm moves (it does "
            "not converge tighter), and with the positions within POSITION_TOL / 2 the tooth forces differ by up to "
            "53 N of 1730 (1 % allowed): the reference is not fine enough here",
        ),
    ),
    ("d2", 800.0, 0.0),
]


def _model(name):
    if name not in _MODELS:
        _MODELS[name] = build_model(build_drive(load_design(ROOT / "templates" / f"{name}.toml")), 3)
    return _MODELS[name]


@pytest.mark.parametrize(
    "name,torque_nm,offset_um",
    CASES,
    ids=[f"{n}-{t:g}Nm-{e:g}um" for n, t, e in (getattr(c, "values", c) for c in CASES)],
)
def test_fast_solver_matches_the_plain_one(name, torque_nm, offset_um):
    m = _model(name)
    ref = plain_solve(m, torque_nm, offset_um)
    st = solve_load(m, torque_nm, offset_um, 0.0, tol=POSITION_TOL / 4)
    z_g = m.drive.design.drive.z_flex
    assert abs(st.rigid[2] - ref["rigid"][2]) < POSITION_TOL / (2 * m.drive.r_m)
    assert np.abs(st.rigid[:2] - ref["rigid"][:2]).max() < POSITION_TOL / 2
    c = st.contacts
    Fb = c["force"][c["kind"] == 0]
    assert np.abs(Fb - ref["ball_force"]).max() < 0.01 * ref["ball_force"].max()
    tooth = (c["kind"] == 1) & (c["force"] > 0)
    got = {
        (int(s_), int(t), int(f)): F
        for s_, t, f, F in zip(c["section"][tooth], c["tooth"][tooth], c["flank"][tooth], c["force"][tooth])
    }
    scale = max(max(ref["tooth_force"].values(), default=0.0), 1.0)
    for key in set(got) | set(ref["tooth_force"]):
        assert abs(got.get(key, 0.0) - ref["tooth_force"].get(key, 0.0)) < 0.01 * scale, key
    phi = 2 * np.pi * np.arange(z_g) / z_g
    for law, (w, v, _) in zip(st.laws, ref["rim"]):
        s = law.state(np.where(phi > np.pi, phi - 2 * np.pi, phi))
        assert np.hypot(s.w - w, s.v - v).max() < POSITION_TOL / 2


@pytest.mark.parametrize("torque_nm", [1500.0, 3000.0])
def test_report_gaps_against_a_full_measurement(torque_nm):
    # the final report measures on the exact geometry every pair that could carry load or hold the smallest
    # clearance and leaves the others linearised; measuring every pair at the solved state must give the same
    # figures for the former, and for the latter exact gaps above the smallest open one (at 3000 N m no open
    # pair is measured at the solved poses before the report: it looks for the nearest first)
    from wgcad.elastic.rim import loads_on_table
    from wgcad.elastic.state import _geometry

    m = _model("d1_involute")
    st = solve_load(m, torque_nm)
    keys, gaps, _ = _geometry(m, loads_on_table(m.tables, st.laws[0].psi, st.laws[0].loads), st.motion)
    full = dict(zip(keys.tolist(), gaps))
    c = st.contacts
    tooth = np.nonzero(c["kind"] == 1)[0]
    k = ((c["section"][tooth] * m.tables.z_g + c["tooth"][tooth]) * 2 + c["flank"][tooth]).tolist()
    ex = c["gap_exact"][tooth]
    assert ex[c["force"][tooth] > 0].all()
    exact_open = [c["gap"][j] for j, e in zip(tooth, ex) if e and c["gap"][j] > 0]
    for j, key, e in zip(tooth, k, ex):
        if e:
            assert abs(c["gap"][j] - full[key]) < 1e-9
        elif key in full:
            assert full[key] > min(exact_open)


def test_teeth_near_engagement_as_from_placed_tips():
    # tooth_poses finds the teeth whose tips reach within RADIAL_MARGIN of the rigid tip circle from |R p + s|^2
    # expanded (no placed copies): the same teeth as placing the tip vertices, and radii equal to round-off
    from wgcad.elastic.rim import RADIAL_MARGIN, loads_on_table, tooth_poses
    from wgcad.placement import transform

    for name in ("d1_involute", "d1_cycloidal"):
        m = _model(name)
        st = solve_load(m, 3000.0)
        loads = loads_on_table(m.tables, st.laws[0].psi, st.laws[0].loads)
        rot, shift, _, _, cand = tooth_poses(m, loads, st.motion.sections)
        tips = transform(m.scene.flex_tip_local, rot, shift)
        R = np.hypot(tips[..., 0], tips[..., 1]).max(axis=1)
        assert np.array_equal(cand, np.nonzero(R >= m.scene.r_tip_b - RADIAL_MARGIN)[0])
        assert 0 < len(cand) < len(R)
