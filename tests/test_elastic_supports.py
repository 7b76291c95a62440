"""The members' supports and the spatial rim of the load model (docs/models.md 4.2): the closed forms they rest on,
every member's equilibrium against its support in solved states, the held and floating limits, and the spatial
model of one plane against the planar one."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wgcad.design import load_design, with_changes
from wgcad.drive import build_drive
from wgcad.elastic import build_model, solve_load
from wgcad.elastic.supports import plate_tilt_stiffness, tube_lateral_compliance, twist_compliance

ROOT = Path(__file__).resolve().parents[1]
D1 = ROOT / "templates" / "d1_involute.toml"


def test_narrow_diaphragm_tilts_as_its_radial_strips():
    # an annulus of width b << r is a ring of radial strips, each a beam clamped at the hub whose outer end
    # follows the tilting wall (deflection r phi cos(theta), slope phi cos(theta)): its energy per unit arc is
    # D/2 (12 d^2/b^3 - 12 d s/b^2 + 4 s^2/b); the plate's Michell solution must approach it as b/r -> 0, with
    # corrections of order b/r (curvature of the annulus)
    E, nu, h = 206e3, 0.3, 1.5
    D = E * h**3 / (12 * (1 - nu**2))
    for r, b in ((100.0, 1.0), (100.0, 0.3)):
        r_m = r + 0.5 * b
        strip = D * np.pi * r_m * (12 * r_m**2 / b**3 - 12 * r_m / b**2 + 4 / b)
        k = plate_tilt_stiffness(r, r + b, h, E, nu)
        assert abs(k / strip - 1) < 3 * b / r, (b, k / strip)


def _plate_fe(r_i, r_o, h, E, nu, elements: int):
    """The n = 1 plate problem by finite elements (an independent solution of the same energy): cubic Hermite
    elements in W(r) (nodal W and W'), the bending energy integrated by 4-point Gauss per element, W and W' fixed at
    both edges; the tilt stiffness is twice the energy at unit tilt."""
    D = E * h**3 / (12 * (1 - nu**2))
    nodes = np.linspace(r_i, r_o, elements + 1)
    N = 2 * (elements + 1)
    H = np.zeros((N, N))
    xg, wg = np.polynomial.legendre.leggauss(4)
    for e in range(elements):
        a, b = nodes[e], nodes[e + 1]
        L = b - a
        for x, w in zip(xg, wg):
            u = 0.5 * (x + 1.0)
            r = a + u * L
            # Hermite basis in u and its derivatives in r
            N0 = np.array(
                [1 - 3 * u**2 + 2 * u**3, L * (u - 2 * u**2 + u**3), 3 * u**2 - 2 * u**3, L * (-(u**2) + u**3)]
            )
            N1 = (
                np.array([-6 * u + 6 * u**2, L * (1 - 4 * u + 3 * u**2), 6 * u - 6 * u**2, L * (-2 * u + 3 * u**2)]) / L
            )
            N2 = np.array([-6 + 12 * u, L * (-4 + 6 * u), 6 - 12 * u, L * (-2 + 6 * u)]) / L**2
            lap = N2 + N1 / r - N0 / r**2
            g = N1 / r - N0 / r**2
            dens = np.outer(lap, lap) - (1 - nu) * (np.outer(N2, g) + np.outer(g, N2)) + 2 * (1 - nu) * np.outer(g, g)
            idx = np.arange(2 * e, 2 * e + 4)
            H[np.ix_(idx, idx)] += 0.5 * D * np.pi * dens * r * w * 0.5 * L
    fixed = np.array([0, 1, N - 2, N - 1])
    vals = np.array([0.0, 0.0, r_o, 1.0])
    free = np.setdiff1d(np.arange(N), fixed)
    x = np.zeros(N)
    x[fixed] = vals
    x[free] = np.linalg.solve(H[np.ix_(free, free)], -H[np.ix_(free, fixed)] @ vals)
    return 2.0 * float(x @ H @ x)


def test_diaphragm_tilt_equals_an_independent_finite_element_plate():
    # the same plate by cubic Hermite elements instead of the closed-form Michell solution: their energy converges
    # as h^4 (16 times closer per halving, checked), and 80 elements are within 1e-7 of the limit (finer meshes
    # meet the round-off of the element matrices, ~1e-8)
    for r_i, r_o, h in ((30.0, 80.0, 1.5), (66.9, 81.0, 1.5), (10.0, 40.0, 0.8)):
        k = plate_tilt_stiffness(r_i, r_o, h, 206e3, 0.3)
        e20, e40, e80 = (_plate_fe(r_i, r_o, h, 206e3, 0.3, elements=n) / k - 1 for n in (20, 40, 80))
        assert abs(e80) < 1e-7, (r_i, r_o, e20, e40, e80)
        if abs(e20) > 1e-7:  # above the assembly's round-off: the h^4 rate
            assert 12 < e20 / e40 < 20, (r_i, r_o, e20, e40)


def test_cup_wall_compliance_is_the_cantilevers():
    EI, kGA, L = 4.1e11, 2.4e7, 130.0
    x = np.array([130.0, 145.0, 160.0, 60.0])
    c = tube_lateral_compliance(x, L, EI, kGA)
    assert np.allclose(c, c.T)
    # at the tube's end: the tip deflection of a clamped cantilever under an end load
    assert abs(c[0, 0] - (L**3 / (3 * EI) + L / kGA)) < 1e-15
    # beyond the end the rim is stiff: a load there is the end load plus its moment (arm a): u = PL^3/3EI + P a
    # L^2/2EI + P L/kGA at the end, and the end's slope carries a point further out
    a = 30.0
    tip = L**3 / (3 * EI) + a * L**2 / (2 * EI) + L / kGA
    slope = L**2 / (2 * EI) + a * L / EI
    assert abs(c[2, 0] - tip) < 1e-15
    assert abs(c[2, 2] - (tip + a * slope)) < 1e-15
    # inside the tube (x = 60 from the base, load at the end): x^2 (3 L - x) / 6 EI + x / kGA
    assert abs(c[3, 0] - (60.0**2 * (3 * L - 60.0) / (6 * EI) + 60.0 / kGA)) < 1e-15


def test_cup_twist_compliance_is_the_torque_path_to_the_diaphragm():
    z = np.array([0.0, 15.0, 30.0, 19.0])
    C = twist_compliance(z, 160.0, [(0.0, 30.0, 2.0e11), (30.0, 160.0, 4.0e11)])
    # a torque at 0 turns the plane at 15 by the twist of the wall from 15 to the diaphragm
    assert abs(C[1, 0] - (15.0 / 2.0e11 + 130.0 / 4.0e11)) < 1e-20
    assert abs(C[0, 0] - (30.0 / 2.0e11 + 130.0 / 4.0e11)) < 1e-20
    assert abs(C[2, 3] - 130.0 / 4.0e11) < 1e-20
    assert np.allclose(C, C.T, rtol=0, atol=1e-25)


SPRUNG = {
    "output_bearing_radial_n_per_mm": 2.0e5,
    "output_bearing_tilt_nm_per_rad": 5.0e6,
    "rigid_gear_radial_n_per_mm": 1.0e6,
    "rigid_gear_tilt_nm_per_rad": 2.0e7,
    "cam_radial_n_per_mm": 5.0e4,
}


def _drive(supports=None, **tables):
    d = load_design(D1)
    if supports:
        tables["supports"] = supports
    return build_drive(with_changes(d, **tables) if tables else d)


def _drive_unchecked(supports: dict):
    """D1 with support stiffnesses beyond the design file's bounds (the limits' tests), not validated."""
    d = load_design(D1)
    return build_drive(replace(d, supports=replace(d.supports, **supports)))


@pytest.fixture(scope="module")
def sprung():
    m = build_model(_drive(SPRUNG), 3)
    return m, [solve_load(m, 0.0, 40.0, 30.0), solve_load(m, 1000.0, 40.0, 30.0), solve_load(m, 3000.0)]


def _columns(st):
    """Every contact's freedom columns rebuilt from the reported contacts (forces, points, normals, planes)."""
    c = st.contacts
    sup = st.model.supports
    n, p = c["normal"], c["point"]
    A3 = np.stack([n[:, 0], n[:, 1], p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0]], axis=1)
    tooth = c["kind"] == 1
    cam = np.where(tooth[:, None], 0.0, -n)
    plane = np.where(tooth, c["section"], sup.ball_plane)
    return sup.columns(A3, cam, plane, tooth)


def test_every_member_balances_its_contacts_against_its_support(sprung):
    # each member (flexspline rim, rigid gear, cam) takes the reported contact forces (points, normals, each along
    # -normal on the rim and +normal on the rigid gear and the cam) and its support's reaction: a free freedom
    # balances the external load (the output torque on the flexspline's rotation), a sprung one moves by its
    # net load over its stiffness (F / k), to round-off
    m, states = sprung
    sup = m.supports
    for st in states:
        A = _columns(st)
        F = st.contacts["force"]
        load = A.T @ F
        f = sup.f_ext(m.torque_sign * 1e3 * st.torque_nm)
        k = sup.stiffness
        scale = np.abs(A * F[:, None]).max(axis=0) + np.abs(f) + 1.0
        for j, name in enumerate(sup.names):
            a = st.freedoms[j]
            if k[j] == 0.0:
                assert abs(load[j] - f[j]) < 1e-9 * scale[j], name
            elif np.isfinite(k[j]):
                assert abs(a - (f[j] - load[j]) / k[j]) * k[j] < 1e-9 * scale[j], (name, a, (f[j] - load[j]) / k[j])
            else:
                assert a == 0.0, name
        # the members did move (the supports are in play, not held by accident): the cam against its offset, the
        # flexspline and the rigid gear under the tooth forces
        g = dict(zip(sup.names, st.freedoms))
        if st.cam_offset.any():
            assert abs(g["cam_x"]) + abs(g["cam_y"]) > 1e-4
        if st.torque_nm > 0:
            assert abs(g["rigid_x"]) + abs(g["rigid_y"]) + abs(g["rigid_tilt_x"]) + abs(g["rigid_tilt_y"]) > 0


def test_a_stiffer_support_moves_its_member_less(sprung):
    # the cam's displacement is its net ball load over its stiffness: doubling the stiffness moves it less, but not
    # to half (the stiffer cam takes more of the offset's load: the drive around it is a spring in series)
    m, states = sprung
    m2 = build_model(_drive({**SPRUNG, "cam_radial_n_per_mm": 1.0e5}), 3)
    a = states[1].motion.cam
    b = solve_load(m2, 1000.0, 40.0, 30.0).motion.cam
    ratio = np.hypot(*b) / np.hypot(*a)
    assert 0.5 < ratio < 1.0


def _random_problem(seed: int, m: int = 40, r: int = 6):
    """A contact problem of a load state's size and magnitudes: compliance ~1e-5 mm/N (SPD), gaps of micrometres
    to a tenth of a millimetre (some closed), rows of contact normals and levers, loads of kN."""
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(m, m))
    M = 1e-5 * (B @ B.T / m + 0.1 * np.eye(m))
    q = rng.uniform(-0.02, 0.1, m)
    A = np.column_stack([rng.normal(size=(m, r - 1)), 80.0 * rng.normal(size=m)])
    f = np.zeros(r)
    f[-1] = 1e6
    return M, q, A, f


@pytest.mark.parametrize("seed", range(5))
def test_support_limits_of_the_contact_problem(seed):
    # k -> inf is the held freedom and k -> 0 the free one, to 1e-9 of the forces: the supports enter as
    # A'F + k a = f (solve.solve_supported), which stays well conditioned at both ends
    from wgcad.elastic.solve import solve_supported

    M, q, A, f = _random_problem(seed)
    base = np.array([0.0, 3e5, 3e5, 2e4, 1e6, 0.0])
    for j, (limit, near) in enumerate(((np.inf, 1e15), (0.0, 1e-9)) * 3):
        j = (j // 2) + 1
        k_lim, k_near = base.copy(), base.copy()
        k_lim[j], k_near[j] = limit, near
        a = solve_supported(M, q, A, f, k_lim)
        b = solve_supported(M, q, A, f, k_near)
        scale = float(np.abs(a.F).max())
        assert np.abs(a.F - b.F).max() < 1e-9 * scale, (seed, j, limit)
        keep = np.arange(len(base)) != j if limit == np.inf else np.ones(len(base), dtype=bool)
        assert np.abs(a.a[keep] - b.a[keep]).max() < 1e-9 * (np.abs(a.a[keep]).max() + 1e-12), (seed, j, limit)
        if limit == np.inf:  # the stiff support moves by its reaction over its stiffness, which is the held one's
            # (the reaction read back from a 1e-12 mm displacement through 1e15 N/mm carries ~1e-9 of round-off)
            reaction = f[j] - A[:, j] @ b.F
            terms = np.abs(A[:, j]) @ np.abs(b.F) + abs(f[j])  # the sum the reaction is taken from
            assert abs(b.a[j] * near - reaction) < 1e-8 * terms
            assert abs(reaction - (f[j] - A[:, j] @ a.F)) < 1e-9 * terms


@pytest.mark.parametrize("key", ["cam_radial_n_per_mm", "rigid_gear_radial_n_per_mm"])
def test_a_stiff_or_soft_support_is_the_held_or_floating_one_in_a_load_state(key):
    # the whole load state: at 1e15 N/mm (F/k ~ 1e-12 mm) the held state, at 1e-6 N/mm the floating one. The two
    # solves iterate to one fixed point each within the position tolerance, through passes whose round-off differs
    # (an extra freedom in the problem): their states agree within that tolerance
    from wgcad.elastic.state import POSITION_TOL

    for near, limit in ((1e15, float("inf")), (1e-6, 0.0)):
        if key == "rigid_gear_radial_n_per_mm" and limit == 0.0:
            continue  # a floating rigid gear with the flexspline sprung is a different drive, not a limit here
        a = solve_load(build_model(_drive_unchecked({**SPRUNG, key: near}), 3), 1000.0, 40.0, 30.0)
        b = solve_load(build_model(_drive_unchecked({**SPRUNG, key: limit}), 3), 1000.0, 40.0, 30.0)
        assert np.abs(a.motion.rim - b.motion.rim).max() < POSITION_TOL
        assert np.abs(a.motion.cam - b.motion.cam).max() < POSITION_TOL
        assert abs(a.wind_up - b.wind_up) * a.model.drive.r_m < POSITION_TOL


def test_the_spatial_model_of_one_plane_is_the_planar_one():
    # the teeth of one section in the bearing's plane (the generator centred on the face): the spatial model's
    # tilts, cup bending and twist act on one plane only, where the planar model holds the rim by the same
    # supports in series. The two iterate through problems equal but for their freedoms' layout (round-off),
    # to one fixed point: they agree far inside the position tolerance (1e-6 of the forces; POSITION_TOL / 1000)
    d = load_design(D1)
    d = with_changes(d, generator={"generator_z": 0.5 * d.drive.face_width}, supports=SPRUNG)
    drive = build_drive(d)
    sp = build_model(drive, 1, rim="spatial")
    pl = build_model(drive, 1, rim="planar")
    assert sp.supports.spatial and not pl.supports.spatial
    for T, e in ((1000.0, 0.0), (2000.0, 30.0)):
        a = solve_load(sp, T, e, 10.0)
        b = solve_load(pl, T, e, 10.0)
        assert np.abs(a.contacts["force"] - b.contacts["force"]).max() < 1e-6 * b.contacts["force"].max()
        assert np.abs(a.rigid[:2] - b.rigid[:2]).max() < 2e-7
        assert abs(a.wind_up - b.wind_up) * drive.r_m < 2e-7
        assert np.abs(a.motion.cam - b.motion.cam).max() < 2e-7


def test_the_cups_tilt_lets_the_open_end_share_differently_than_the_planar_rim():
    # the spatial rim is not the planar one on a real cup: the sections move by the cup's tilt and bending, so
    # their loads differ (the check that the spatial terms act at all)
    drive = _drive()
    sp = solve_load(build_model(drive, 3, rim="spatial"), 2000.0, 40.0, 0.0)
    pl = solve_load(build_model(drive, 3, rim="planar"), 2000.0, 40.0, 0.0)

    def per_section(st):
        c = st.contacts
        t = c["kind"] == 1
        out = np.zeros(3)
        np.add.at(out, c["section"][t], c["force"][t])
        return out / out.sum()

    assert np.abs(per_section(sp) - per_section(pl)).max() > 1e-3
    assert np.ptp(sp.motion.rim[:3, 0]) > 1e-6  # the sections move apart (the cup's tilt and bending)


def test_zone_shares_of_a_centred_perfect_drive_are_equal():
    # D1 is symmetric about its axis with the cam centred: each engagement zone carries half the torque, and the
    # zones' torques sum to the output torque less the balls' share (the generator torque, a percent)
    st = solve_load(build_model(_drive(), 3), 1000.0)
    share = st.zone_share()
    assert np.allclose(share, 0.5, atol=1e-6)
    assert abs(st.zone_torque().sum() - 1e6) < 0.03 * 1e6


def test_stiffness_keys_are_checked(tmp_path):
    from wgcad.errors import DesignError

    d = load_design(D1)
    with pytest.raises(DesignError, match="supports.cam_radial_n_per_mm"):
        with_changes(d, supports={"cam_radial_n_per_mm": -1.0})
    with pytest.raises(DesignError, match="supports.rim"):
        with_changes(d, supports={"rim": "curved"})
    text = D1.read_text() + "\n[supports]\ncam_radial_n_per_mm = inf\nrigid_gear_radial_n_per_mm = 3e5\n"
    p = tmp_path / "d.toml"
    p.write_text(text)
    got = load_design(p).supports
    assert got.cam_radial_n_per_mm == float("inf") and got.rigid_gear_radial_n_per_mm == 3e5
    p.write_text(D1.read_text() + "\n[supports]\ncam_radial_n_per_mm = 1e13\n")
    with pytest.raises(DesignError, match="cam_radial_n_per_mm"):
        load_design(p)
    p.write_text(D1.read_text() + "\n[supports]\nrigid_gear_seat_mm = inf\n")
    with pytest.raises(DesignError, match="rigid_gear_seat_mm"):
        load_design(p)
    assert replace(got, rim="planar").rim == "planar"


ELASTIC_TEMPLATES = [
    "d1_involute",
    "d1_involute_nominal",
    "d1_cycloidal",
    "d1_double_arc",
    "d1_conjugate",
    "d1_conjugate_modified",
    "d2",
    "d2_imperfect",
]


def _same_state(a, b, drive, what):
    """Two solutions of one load state agree within the position tolerance: the motions within it, each contact's
    force within that tolerance times the contact's own stiffness (its force over its approach: a conformal
    conjugate flank is stiffer than an involute one) plus 1 N."""
    from wgcad.elastic.state import POSITION_TOL

    assert np.abs(a.motion.rim - b.motion.rim).max() < POSITION_TOL, what
    assert abs(a.wind_up - b.wind_up) * drive.r_m < POSITION_TOL, what

    def by_key(st):
        c = st.contacts
        keys = zip(c["kind"], c["section"], c["tooth"], c["flank"], c["phi"].round(9))
        return {k: (f, ap) for k, f, ap in zip(keys, c["force"], c["approach"])}

    ka, kb = by_key(a), by_key(b)
    for k in set(ka) | set(kb):
        Fa, apa = ka.get(k, (0.0, 0.0))
        Fb, apb = kb.get(k, (0.0, 0.0))
        stiff = max(Fa / apa if apa > 0 else 0.0, Fb / apb if apb > 0 else 0.0)
        assert abs(Fa - Fb) < 2.0 * POSITION_TOL * stiff + 1.0, (what, k, Fa, Fb)


@pytest.mark.parametrize("name", ELASTIC_TEMPLATES)
def test_warm_started_states_equal_cold_ones_on_every_template(name):
    # the fast path against the reference (every state from scratch: the mounted rim, a fresh model with no cached
    # pairs); both iterate to one fixed point within the position tolerance. The fast paths: each torque
    # warm-started from the last (pairs, forces and motions carried over), and the state solved again from itself
    # (the same torque: its tooth forces carried too, the first pass linearising the flanks about them and
    # starting from the teeth they load)
    drive = build_drive(load_design(ROOT / "templates" / f"{name}.toml"))
    fast = build_model(drive, 3)
    warm = None
    for T in (300.0, 900.0, 1800.0):
        a = solve_load(fast, T, warm=warm)
        warm = a
        b = solve_load(build_model(drive, 3), T)
        _same_state(a, b, drive, (name, T))
        _same_state(solve_load(fast, T, warm=a), b, drive, (name, T, "again"))
