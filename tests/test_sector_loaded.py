"""The elastic model on the sectored rigid gear (wgcad/sector/loaded.py, transition.py; docs/models.md 2.3, 4.1): the
adapter against the plain drive's model, its contacts against the clearance engine tooth by tooth, the settled states,
and the transitions under load of the bundled drive."""

from math import pi

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
from wgcad.profiles.sector import SectorLayout
from wgcad.sector import motion_law
from wgcad.sector.built import built_gear
from wgcad.sector.loaded import SETTLE_TOL, SectorContactScene, sector_model, solve_knot
from wgcad.sector.transition import loaded_cycle, transition_figures

T_NM = 2.0  # the template's torque


@pytest.fixture(scope="module")
def d4():
    design = load_design(TEMPLATES / "d4_sectored.toml")
    drive = build_drive(design)
    gear = built_gear(design, drive=drive)
    return design, drive, gear, build_model(drive)


def _plain_layout(z_b: int) -> SectorLayout:
    c = (np.arange(z_b) + 0.5) * 2 * pi / z_b  # the plain scene's tooth centres: a space on +x
    return SectorLayout(
        c,
        np.zeros(z_b, int),
        np.arange(z_b),
        np.zeros(z_b, bool),
        np.full(z_b, 2 * pi / z_b),
        np.zeros(z_b),
        np.array([0.0, 2 * pi]),
        ("transmission",),
        c + pi / z_b,
    )


def test_a_plain_gear_posed_by_the_adapter_is_the_plain_drive(d4):
    """The adapter's scene of a one-kind layout at the plain gear's pitch, full teeth, generator at 0: the plain drive's
    elastic model must give the same state, force for force (the rigid teeth through the shape set, the neighbours
    by search: other code than the plain scene's)."""
    design, drive, gear, model = d4
    teeth = gear["teeth"]
    lay = _plain_layout(88)
    scene = SectorContactScene(model.scene, lay, teeth, np.full(88, teeth.height), 0.0)
    a = solve_load(sector_model(model, scene), T_NM)
    b = solve_load(build_model(drive), T_NM)
    assert a.rigid == pytest.approx(b.rigid, abs=1e-12)
    fa, fb = a.contacts["force"], b.contacts["force"]
    assert len(fa) == len(fb) and np.abs(fa - fb).max() < 1e-9
    assert (b.contacts["force"][b.contacts["kind"] == 1] > 0).sum() >= 2


def test_lowered_teeth_are_measured_against_their_own_outlines(d4):
    """A transition state where a lowered coupling tooth carries load: the solver's gaps equal the clearance engine's,
    each rigid tooth against its own (lowered) outline; the same state with full teeth differs (the outlines matter)."""
    design, drive, gear, model = d4
    lay, teeth, built = gear["layout"], gear["teeth"], gear["built"]
    law = motion_law(lay, 84)
    knot = float(law.knots[7])  # 34.3 deg: the mesh holds the lowered teeth 4 .. 7 of the first coupling sector
    ks = solve_knot(model, gear, built, law, knot, T_NM)
    low = built < teeth.height - 1e-9
    assert ks.rigid_forces[low].max() > 10.0
    assert ks.check_mm < 1e-9
    full = solve_knot(model, gear, np.full(lay.n_teeth, teeth.height), law, knot, T_NM)
    assert abs(full.rim_rotation - ks.rim_rotation) > 1e-5  # tens of arcsec: the lowered tips change the state


def test_settled_state_and_identical_waves(d4):
    """solve_knot leaves the elastic model's rigid turn of the rim below SETTLE_TOL at a tooth, and a wave later the
    settled state is the same (the scene turned by pi: rigid tooth i + 43 for i)."""
    design, drive, gear, model = d4
    law = motion_law(gear["layout"], 84)
    a = solve_knot(model, gear, gear["built"], law, float(law.knots[0]), T_NM)
    b = solve_knot(model, gear, gear["built"], law, float(law.knots[43]), T_NM)
    assert abs(a.residual_rotation) * drive.r_m < SETTLE_TOL and a.solves >= 2  # 0.3 deg of free play: settled
    assert abs(a.rim_rotation) > 1e-3
    assert b.knot - a.knot == pytest.approx(pi, abs=1e-12)
    assert b.output_loaded - b.output_kinematic == pytest.approx(a.output_loaded - a.output_kinematic, abs=1e-9)
    np.testing.assert_allclose(np.roll(a.rigid_forces, 43), b.rigid_forces, atol=1e-6)


@pytest.fixture(scope="module")
def cycle(d4):
    design, drive, gear, model = d4
    cy = loaded_cycle(gear, T_NM, model=model)
    return cy, transition_figures(cy, gear["layout"], gear["full"])


def test_transmission_interior_is_the_plain_drive_loaded(d4, cycle):
    """Deep in a transmission sector (the mesh reaches only its teeth) the loaded state repeats from knot to knot as the
    plain 84/88 drive's does at whole mesh periods: same rim rotation and same largest force at every interior knot."""
    design, drive, gear, model = d4
    cy, fig = cycle
    lay = gear["layout"]
    phi = cy.phi_h % pi
    inner = (phi > pi / 2 + fig.reach + 0.01) & (phi < pi - fig.reach - 0.01)
    assert inner.sum() >= 3
    dev = cy.deviation[inner]
    settle = 2 * SETTLE_TOL / drive.r_m  # where each settled state stops: 0.2 um at a tooth, either way
    assert np.ptp(dev) < settle and np.ptp(cy.rigid_forces[inner].max(axis=1)) < 0.05
    # the plain drive at generator angle 0, settled the same way: a layout of one kind at the 88-tooth pitch
    plain = dict(gear, layout=_plain_layout(88), built=np.full(88, gear["full"]))
    st = solve_knot(model, plain, plain["built"], motion_law(plain["layout"], 84), 0.0, T_NM)
    assert st.rim_rotation == pytest.approx(cy.rim_rotation[inner][0], abs=settle)
    assert st.rigid_forces.max() == pytest.approx(cy.rigid_forces[inner][0].max(), rel=1e-3)
    assert lay.n_teeth == 86


def test_transition_figures_of_the_bundled_drive(d4, cycle):
    """The figures the README quotes, as properties: the load's part of the output steps most at a boundary (hundreds
    of arcsec: the free play taken up) and less inside a sector, where only the lowered teeth make it step; the
    lowered teeth carry load; every state measured exactly."""
    design, drive, gear, model = d4
    cy, fig = cycle
    assert len(cy.phi_h) == 43 and cy.check_mm < 1e-9
    assert np.all(np.abs(cy.residual_rotation) * drive.r_m < SETTLE_TOL)
    assert abs(fig.output_jump_boundary) > 2 * abs(fig.output_jump_interior)
    assert abs(fig.output_jump_boundary) > np.deg2rad(100 / 3600)  # hundreds of arcsec: the free play taken up
    assert fig.lowered_force > 0 and gear["built"][fig.lowered_tooth] < gear["full"]
    assert 0.3 < fig.reach < 0.7  # the mesh reaches 20-40 deg from the axis
    assert fig.steps_boundary + fig.steps_interior == 43
