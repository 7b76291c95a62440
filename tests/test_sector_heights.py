"""Variable tooth heights of the sectored rigid gear (docs/models.md 2.3): closed form and simulation, their properties and agreement."""

from math import pi

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.design import load_design
from wgcad.drive import build_drive, tooth_spec
from wgcad.placement import tooth_pose, transform
from wgcad.profiles.sector import TeethByHeight, sector_layout, sectored_outline
from wgcad.sector import closed_form_heights, simulated_heights

STEP_DEG = 0.25  # sweep step of these tests (the CLI default is 0.1)
C_REQ = 0.010  # tip clearance of the template, mm


@pytest.fixture(scope="module")
def d4():
    design = load_design(TEMPLATES / "d4_sectored.toml")
    drive = build_drive(design)
    lay = sector_layout(design.sectors, design.drive.z_flex, design.drive.z_rigid)
    teeth = TeethByHeight(tooth_spec(design, "rigid"), drive.rigid)
    res = {
        "design": design,
        "drive": drive,
        "layout": lay,
        "teeth": teeth,
        "boundary": closed_form_heights(drive, lay, teeth, assign="boundary"),
        "register": closed_form_heights(drive, lay, teeth, assign="register", step_deg=STEP_DEG),
        "sim": simulated_heights(drive, lay, teeth, C_REQ, step_deg=STEP_DEG),
        "sim0": simulated_heights(drive, lay, teeth, 0.0, step_deg=STEP_DEG),
    }
    return res


def _sampling_tol(drive) -> float:
    """How far a height found on a sweep of STEP_DEG can sit from the continuous one: the flexspline tip's radius moves by at
    most max|w'| per rad of its angle, and the sampled angle is off by at most one step (plus the 0.1 um bisection)."""
    phi = np.linspace(0.0, pi / 2, 20001)
    return float(np.abs(drive.law.state(phi).dw).max()) * np.deg2rad(STEP_DEG) + 1e-4


def _coupling_sectors(lay):
    return [lay.coupling_sector_teeth(s) for s in range(len(lay.kinds)) if lay.kinds[s] == "coupling"]


@pytest.mark.parametrize("method", ["boundary", "register", "sim", "sim0"])
def test_heights_never_above_full_and_positive(d4, method):
    h = d4[method].heights
    H = d4["teeth"].height
    assert np.all(h <= H + 1e-12) and np.all(h > 0)
    assert abs(H - 0.7) < 1e-12  # m (2 h_a* + c*) = 0.4 (1.5 + 0.25)


@pytest.mark.parametrize("method,tol", [("boundary", 1e-12), ("register", 1e-9), ("sim", 1e-4), ("sim0", 1e-4)])
def test_heights_symmetric_about_sector_middle_and_equal_between_sectors(d4, method, tol):
    # the sweep grid (k * STEP_DEG) is symmetric about the sector middles (45 and 225 deg), so mirrored teeth see mirrored
    # samples: equal to rounding (closed forms) or to the bisection tolerance 0.1 um (simulation); no symmetry is assumed
    h = d4[method].heights
    a, b = _coupling_sectors(d4["layout"])
    assert np.allclose(h[a], h[a][::-1], rtol=0, atol=tol)
    assert np.allclose(h[a], h[b], rtol=0, atol=tol)


def test_boundary_closed_form_monotone_from_boundary_to_middle_full_in_middle(d4):
    lay = d4["layout"]
    for s in _coupling_sectors(lay):
        h = d4["boundary"].heights[s]
        half = h[: len(h) // 2 + 1]
        assert np.all(np.diff(half) > 0) or np.all(np.diff(half) >= 0)
        assert np.all(np.diff(half)[: np.argmax(half >= d4["teeth"].height - 1e-12)] > 0)
        assert h[len(h) // 2] == pytest.approx(d4["teeth"].height)
        assert h[0] < 0.2 * d4["teeth"].height  # at the boundary W0 = 2 m pushes the tip far in


@pytest.mark.parametrize("method", ["register", "sim", "sim0"])
def test_swept_heights_monotone_from_boundary_to_middle_within_sampling(d4, method):
    # D4 finding: these heights are flat over the sector (the wave's own tangential displacement inside a coupling sector,
    # not the sector change, sets them), so "monotone" holds only to the sweep's sampling error
    tol = _sampling_tol(d4["drive"])
    for s in _coupling_sectors(d4["layout"]):
        h = d4[method].heights[s]
        half = h[: len(h) // 2 + 1]
        drops = np.maximum(0.0, half[:-1] - half[1:])
        assert drops.max() <= tol, (drops.max(), tol)
        assert np.ptp(h) <= tol


def test_closed_form_parameters_explicit(d4):
    cf, drive = d4["register"], d4["drive"]
    assert cf.r_fix == pytest.approx(drive.rigid.r_f)  # root radius of the rigid gear 18.4 mm
    assert cf.r_cr == pytest.approx(drive.r_m)
    assert cf.h_s == pytest.approx(drive.flex.r_a - drive.r_m)
    assert cf.w0 == pytest.approx(0.8) and cf.beta == pytest.approx(np.deg2rad(30.0))
    lay = d4["layout"]
    i = lay.coupling_sector_teeth()
    assert np.all(np.isfinite(cf.phi_h[i])) and np.all(np.isfinite(cf.phi[i]))
    assert np.all(np.abs(cf.phi[i]) <= pi / 2)


def test_closed_form_is_the_deformed_tip_radius(d4):
    """r_ari = r_cr + w + h_s against the radius of the placed flexspline tooth's tip centre (tooth_pose, exact placement):
    they differ only by the tangential terms, (v + h_s theta)^2 / (2 r) to first order."""
    cf, drive = d4["register"], d4["drive"]
    i = np.nonzero(np.isfinite(cf.phi))[0]
    phi = cf.phi[i]
    rot, shift = tooth_pose(drive.law, phi, drive.r_m)
    tip = transform(np.array([[drive.flex.r_a, 0.0]]), rot, shift)[:, 0, :]
    r_exact = np.hypot(tip[:, 0], tip[:, 1])
    r_form = cf.r_fix - cf.heights[i]
    st = drive.law.state(phi)
    bound = (np.abs(st.v) + cf.h_s * np.abs(st.theta)) ** 2 / (2 * drive.r_m) + 1e-9
    full = cf.heights[i] >= d4["teeth"].height - 1e-12
    assert np.all(np.abs(r_exact - r_form)[~full] <= bound[~full])


def test_simulated_against_closed_form(d4):
    """With zero clearance the simulation lowers each tooth to where the whole placed flexspline tooth clears it; the
    closed form puts the tip at the tooth's centre-line tip radius. The tip corners of the tooth, turned by theta, reach
    at most (s_tip / 2) |theta| further, and both are sampled on the same sweep."""
    sim0, cf, drive = d4["sim0"], d4["register"], d4["drive"]
    at_risk = np.isfinite(cf.phi)
    phi = np.linspace(0, pi / 2, 2001)
    corner = 0.5 * drive.flex.tip_thickness * np.abs(drive.law.state(phi).theta).max()
    d = sim0.heights - cf.heights
    tol = _sampling_tol(drive)
    assert np.all(d[at_risk] <= tol)
    assert np.all(d[at_risk] >= -(corner + 2 * tol)), (d.min(), corner)
    # the required clearance lowers the simulated heights by that much, tooth by tooth
    assert np.allclose(d4["sim"].heights[at_risk], sim0.heights[at_risk] - C_REQ, atol=2e-4)


def test_transmission_joint_teeth_found_at_risk_middle_teeth_full(d4):
    lay = d4["layout"]
    H = d4["teeth"].height
    for method in ("register", "sim"):
        h = d4[method].heights
        low_t = np.nonzero(~lay.coupling & (h < H - 1e-12))[0]
        # only the first and last tooth of each transmission sector (next to a joint)
        assert set(lay.index[low_t]) <= {0, 21}
        assert len(low_t) == 4


def test_outline_tips_at_the_built_heights(d4):
    lay, teeth = d4["layout"], d4["teeth"]
    h = d4["sim"].heights
    out = sectored_outline(lay, teeth, h)
    R = np.hypot(out[:, 0], out[:, 1])
    a = np.arctan2(out[:, 1], out[:, 0])
    for i in range(lay.n_teeth):
        near = np.abs((a - lay.centres[i] + pi) % (2 * pi) - pi) < 0.25 * lay.pitch[i]
        # the tip land of an internal tooth is its innermost arc: r_f - h, to the 1 um chord tolerance
        assert R[near].min() == pytest.approx(teeth.full.r_f - h[i], abs=1e-9)
