"""The no-load KE's pieces against independent computations (docs/models.md 6.2, 7).

- every sample's first contact against the lowest closing rotation over *every* contact of its lattice class,
  with each error term from :func:`wgcad.accuracy.ke_lanes.error_terms` (no lanes, no harmonics, no pruning);
- the harmonic form against those error terms, group by group, at random samples and installation angles;
- the KE against its definition from the two first contacts, and against the exact poses (no table);
- the installation-angle scan and the optimiser against the KE recomputed at each angle;
- the spectrum of a planted wave, the orders' closed forms, the refusals.

The tables (N = 4, errors of 5-20 um) are built once per process and handed out as copies without the caches
the KE's functions keep with a table, so each check runs those functions afresh.
"""

import copy
import functools
import math
import tomllib

import numpy as np
import pytest
from conftest import TEMPLATES, edit_toml

from wgcad.accuracy import ke as K
from wgcad.accuracy import ke_lanes as L
from wgcad.design import load_design
from wgcad.design.schema import parse_design
from wgcad.drive import build_drive
from wgcad.errors import DesignError, ModelError
from wgcad.placement.imperfect import Imperfections

AS = 180.0 / math.pi * 3600.0
#: tens of micrometres: contacts of one lattice class trade places, so the pruning bounds decide
BIG = Imperfections(
    rigid_runout=0.02,
    rigid_runout_phase=0.4,
    flex_runout=0.015,
    flex_runout_phase=1.3,
    rigid_ecc=0.01,
    rigid_ecc_phase=2.2,
    flex_ecc=0.008,
    flex_ecc_phase=-0.7,
    cam_fixed=0.006,
    cam_fixed_phase=0.9,
    cam_flex=0.005,
    cam_flex_phase=2.5,
)
#: coned with three sections; straight with one; D4 with 87 and 89 teeth at N = 3 (an odd lattice, z_g N = 261:
#: the folds by half a turn of the lattice, M // 2, are not half of M)
NAMES = ["d2_imperfect", "d4_discrete", "d4_odd"]
#: two sums of the same ~1e-3 rad terms in another order: ulp 2e-19 rad, a few hundred terms
SAME = 1e-15
_CACHES = ("_harmonic_factors", "_lane_factors", "_wave_cache", "_class_waves")


@functools.cache
def _drive(name):
    if name == "d4_odd":
        text = (TEMPLATES / "d4_discrete.toml").read_text(encoding="utf-8")
        text = edit_toml(edit_toml(text, "drive", "z_flex", "87"), "drive", "z_rigid", "89")
        return build_drive(parse_design(tomllib.loads(text), source="d4_discrete with 87/89 teeth"))
    return build_drive(load_design(TEMPLATES / f"{name}.toml"))


@functools.cache
def _built(name):
    return K.contact_table(_drive(name), BIG, 3 if name == "d4_odd" else 4)


def _table(name):
    """A copy of the table without the caches (the arrays are shared, never written)."""
    return _copy_sides(_built(name))


def _scaled(imp, f):
    amps = ("flex_runout", "rigid_runout", "flex_ecc", "rigid_ecc", "cam_flex", "cam_fixed")
    return imp.replace(**{a: f * getattr(imp, a) for a in amps})


def _class_of(tab, i):
    """The lattice class (``m mod N``) of the contacts that can touch at samples ``i``."""
    return (-tab.sigma * np.asarray(i)) % tab.N


def _terms(tab, side, imp, i, e):
    """The closing rotation of contacts ``e`` (I, C) at samples ``i`` (I, 1), term by term."""
    g = tab.sides[side]["g"][e]
    return g + sum(L.error_terms(tab, side, imp, i, e, w) for w in ("rigid", "flex", "cam"))


def _brute(tab, side, imp, i):
    """The lowest closing rotation over every contact of each sample's class, and which contact it is."""
    S = tab.sides[side]
    cls = _class_of(tab, i)
    val = np.full(len(i), np.inf)
    arg = np.full(len(i), -1)
    for r in np.unique(cls):
        rows = np.nonzero(cls == r)[0]
        e = np.nonzero(S["m"] % tab.N == r)[0]
        if e.size:
            v = _terms(tab, side, imp, i[rows][:, None], np.broadcast_to(e, (len(rows), len(e))))
            val[rows] = v.min(axis=1)
            arg[rows] = e[np.argmin(v, axis=1)]
    return val, arg


def _waves(tab, i):
    """The three waves as docs/models.md 7 defines them: ``s`` whole rigid pitches turned at sample ``i``."""
    i = np.asarray(i)
    s = (_class_of(tab, i) + tab.sigma * i) / tab.N
    phi_h = 2 * math.pi * tab.sigma * i / (tab.z_b * tab.N)
    phi_g = phi_h * (tab.z_b - tab.z_g) / -tab.z_g  # phi_h / u_hg, u_hg = -z_g / (z_b - z_g)
    ab, ag = 2 * math.pi * s / tab.z_b, 2 * math.pi * s / tab.z_g
    return np.exp(1j * np.stack([ab, ag, ab - phi_g], axis=-1))


@pytest.mark.parametrize("scale", [1.0, 0.1])
@pytest.mark.parametrize("name", NAMES)
def test_every_first_contact_is_the_lowest_of_its_class(name, scale):
    tab, imp = _table(name), _scaled(BIG, scale)
    I = 3 * tab.N * tab.z_b + 5
    res = K.kinematic_error(_drive(name), imp, table=tab, samples=I)
    ref = K.kinematic_error(_drive(name), imp, table=_table(name), samples=I, reference=True)
    i = np.arange(I)
    dw, aw = _brute(tab, tab.side_w, imp, i)
    dn, an = _brute(tab, -tab.side_w, imp, i)
    for r in (res, ref):
        np.testing.assert_allclose(r.delta_w, dw, rtol=0, atol=SAME)
        np.testing.assert_allclose(r.delta_n, dn, rtol=0, atol=SAME)
    # the two first contacts give the rest (docs/models.md 6.1): LM = dw + dn,
    # theta = s_w (dw - min(LM, 0) / 2), KE = -(theta - theta_0), phi_h = sigma 2 pi i / (z_b N)
    lm = dw + dn
    theta = tab.side_w * (dw - np.minimum(lm, 0.0) / 2)
    np.testing.assert_allclose(res.lost_motion, lm, rtol=0, atol=2 * SAME)
    np.testing.assert_allclose(res.ke, -(theta - theta[0]), rtol=0, atol=4 * SAME)
    np.testing.assert_allclose(res.phi_h, tab.sigma * 2 * math.pi * i / (tab.z_b * tab.N), rtol=1e-15, atol=0)
    u = tab.z_g / (tab.z_b - tab.z_g)
    assert (res.n_per_mesh, res.u) == (tab.N, u)
    assert res.turns == pytest.approx(I / (tab.N * tab.z_b), rel=1e-15)
    assert res.ke_pp == pytest.approx(np.ptp(-(theta - theta[0])), rel=1e-12)
    want = "single-flank (backlash)" if lm.min() >= 0 else "double-flank (interference)" if lm.max() < 0 else "mixed"
    assert res.engagement == want
    # the errors are large enough that the first contact of a class changes along the record
    assert len(np.unique(aw)) > tab.N and len(np.unique(an)) > tab.N


@pytest.mark.parametrize("name", NAMES)
def test_a_whole_record_is_one_flexspline_turn(name):
    tab = _table(name)
    res = K.kinematic_error(_drive(name), BIG, table=tab)
    u = tab.z_g / (tab.z_b - tab.z_g)
    # a flexspline turn is N z_b |u_hg| generator samples, rounded up where that is not whole (87/89 teeth: 11614.5)
    whole = tab.N * tab.z_b * u
    assert len(res.ke) == math.ceil(whole - 1e-9)
    assert res.flex_turns_per_record == pytest.approx(len(res.ke) / whole, rel=1e-12)
    # the block search in its passes of 65 536 samples (D2's record takes two) finds the same first contacts
    ref = K.kinematic_error(_drive(name), BIG, table=_table(name), reference=True)
    for a, b in ((ref.delta_w, res.delta_w), (ref.delta_n, res.delta_n), (ref.ke, res.ke)):
        np.testing.assert_allclose(a, b, rtol=0, atol=4 * SAME)
    if whole != len(res.ke):
        return
    # a whole record ends one sample short of where it started (the KE of a turn closes on itself)
    dw, _ = _brute(tab, tab.side_w, BIG, np.array([len(res.ke), len(res.ke) - 1]))
    assert dw[0] == pytest.approx(res.delta_w[0], abs=SAME) and dw[1] == pytest.approx(res.delta_w[-1], abs=SAME)


def test_the_deep_overlaps_are_the_samples_whose_first_contact_overlaps_deeply():
    # contacts of one class made to overlap by twice the trusted depth: they are first wherever their class
    # is, on the working side; the fraction is the share of samples of that class
    tab = _table("d4_discrete")
    S = dict(tab.sides[tab.side_w])
    lowered = S["m"] % tab.N == 1
    S["g"] = np.where(lowered, S["g"] - 2 * K.DEEP_OVERLAP, S["g"])
    tab.sides = {**tab.sides, tab.side_w: S}
    I = 2 * tab.N * tab.z_b
    for reference in (False, True):
        res = K.kinematic_error(_drive("d4_discrete"), BIG, table=_copy_sides(tab), samples=I, reference=reference)
        _, arg = _brute(tab, tab.side_w, BIG, np.arange(I))
        deep = (arg >= 0) & (S["g"][np.maximum(arg, 0)] < -K.DEEP_OVERLAP)
        assert res.deep_overlap_fraction == pytest.approx(deep.mean(), abs=1e-15)
        assert res.deep_overlap_fraction == pytest.approx(0.25, abs=1e-12)


def test_the_first_contact_at_index_zero_is_flagged_when_it_overlaps_deeply():
    # contact 0 alone lowered by three times the trusted depth: the first of its class at every sample of it
    tab = _table("d4_discrete")
    S = dict(tab.sides[tab.side_w])
    S["g"] = S["g"].copy()
    S["g"][0] -= 3 * K.DEEP_OVERLAP
    tab.sides = {**tab.sides, tab.side_w: S}
    I = 2 * tab.N * tab.z_b
    share = np.mean(_class_of(tab, np.arange(I)) == S["m"][0] % tab.N)
    for reference in (False, True):
        res = K.kinematic_error(_drive("d4_discrete"), BIG, table=_copy_sides(tab), samples=I, reference=reference)
        assert res.deep_overlap_fraction == pytest.approx(share, abs=1e-12)


def _copy_sides(tab):
    """A shallow copy of ``tab`` without the caches the KE's functions keep with a table."""
    out = copy.copy(tab)
    for key in _CACHES:
        out.__dict__.pop(key, None)
    return out


@pytest.mark.parametrize("group", ["rigid", "flex", "cam"])
@pytest.mark.parametrize("name", NAMES)
def test_the_harmonic_form_is_the_error_terms(name, group):
    rng = np.random.default_rng(7)
    tab = _table(name)
    for trial in range(3):
        ph = rng.uniform(-math.pi, math.pi, 8)
        imp = BIG.replace(
            cam_cam=0.01 * trial,  # in the table exactly (the poses): in neither linear form
            cam_cam_phase=ph[0],
            rigid_runout_phase=ph[0],
            flex_runout_phase=ph[1],
            rigid_ecc_phase=ph[2],
            flex_ecc_phase=ph[3],
            cam_fixed_phase=ph[4],
            cam_flex_phase=ph[5],
            rigid_install=ph[6] + math.pi,
            flex_install=ph[7] + math.pi,
        )
        for side in (1, -1):
            S = tab.sides[side]
            i = rng.integers(0, 40 * tab.N * tab.z_b, 24)
            A = L.harmonics(tab, side, imp, groups=(group,))
            assert A.shape == (len(S["g"]), L.N_WAVES)
            w = _waves(tab, i)
            for k in range(len(i)):
                e = np.nonzero(S["m"] % tab.N == _class_of(tab, i[k]))[0]
                ref = L.error_terms(tab, side, imp, np.array([[i[k]]]), e[None, :], group)[0]
                np.testing.assert_allclose((A[e] @ w[k]).real, ref, rtol=0, atol=1e-14)
                assert np.abs(ref).max() > 1e-7  # the group moves these contacts (microradians)
            # only the rows asked for, the same values
            some = np.arange(0, len(S["g"]), 5)
            np.testing.assert_array_equal(L.harmonics(tab, side, imp, groups=(group,), contacts=some), A[some])


@pytest.mark.parametrize("name", NAMES)
def test_harmonic_terms_read_each_lane_and_leave_the_padding_at_zero(name):
    tab = _table(name)
    side = tab.side_w
    lanes = L.candidate_lanes(tab, side, BIG)
    A = L.harmonics(tab, side, BIG)
    i = np.arange(5, 5 + 7 * tab.N)
    got = L.harmonic_terms(tab, lanes, A, i)
    w = _waves(tab, i)
    for k in range(len(i)):
        e = lanes[i[k] % tab.N]
        want = np.where(e >= 0, (A[np.maximum(e, 0)] @ w[k]).real, 0.0)
        np.testing.assert_allclose(got[k], want, rtol=0, atol=1e-15)
    assert (lanes < 0).any()  # some padding was read


@pytest.mark.parametrize("name", NAMES)
def test_the_lanes_hold_each_class_first_contact_and_drop_most(name):
    tab = _table(name)
    for side in (1, -1):
        S = tab.sides[side]
        lanes = L.candidate_lanes(tab, side, BIG)
        assert lanes.shape[0] == tab.N
        for r in range(tab.N):
            e = lanes[r][lanes[r] >= 0]
            every = np.nonzero(S["m"] % tab.N == _class_of(tab, r))[0]
            assert set(e) <= set(every) and len(set(e)) == len(e)
            assert 0 < len(e) < 0.5 * len(every)  # the bounds drop most contacts
            # samples of the class: the lowest over every contact is a lane (and so the lanes' minimum is it)
            i = r + tab.N * np.arange(0, 60 * tab.z_b, 7)
            _, arg = _brute(tab, side, BIG, i)
            assert set(arg) <= set(e)
        # without errors only the contacts whose perfect closing rotation is the class's lowest remain
        lanes0 = L.candidate_lanes(tab, side, Imperfections())
        for r in range(tab.N):
            every = np.nonzero(S["m"] % tab.N == _class_of(tab, r))[0]
            e = lanes0[r][lanes0[r] >= 0]
            assert np.all(np.abs(S["g"][e] - S["g"][every].min()) <= 1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_undominated_lanes_are_those_no_other_lane_stays_below(seed):
    # random problems: lane e stays above d at every sample once g_e - g_d > sum |A_e - A_d| (|w| = 1);
    # the lanes kept are exactly those no other lane of their class dominates (dominance is transitive)
    rng = np.random.default_rng(seed)
    E, N, C = 300, 5, 40
    g = rng.normal(0, 1.0, E)
    A = rng.normal(0, 0.05 * (1 + seed), (E, 3)) + 1j * rng.normal(0, 0.05 * (1 + seed), (E, 3))
    lanes = np.full((N, C), -1)
    for r in range(N):
        n = rng.integers(1, C + 1)
        lanes[r, :n] = rng.choice(E, n, replace=False)
        rng.shuffle(lanes[r])
    got = L.undominated(lanes, A, g)
    for r in range(N):
        e = lanes[r][lanes[r] >= 0]
        for c, x in enumerate(lanes[r]):
            if x < 0:
                assert not got[r, c]
                continue
            dominated = any(g[x] - g[d] > np.abs(A[x] - A[d]).sum() + 1e-15 for d in e if d != x)
            assert got[r, c] == (not dominated), (r, c)
    assert got.sum() < (lanes >= 0).sum()  # something was dropped


def test_equal_lanes_do_not_drop_each_other():
    g = np.array([1.0, 1.0, 1.0 + 1e-16, 5.0])
    A = np.zeros((4, 3), dtype=complex)
    got = L.undominated(np.array([[0, 1, 2, 3]]), A, g)
    assert got.tolist() == [[True, True, True, False]]


@pytest.mark.parametrize("block", [1, 3, 16])
@pytest.mark.parametrize("amp", [1e-6, 1e-3, 1e-1])
def test_lane_minimum_is_the_minimum_over_every_lane(block, amp):
    # random coefficients on a real table's lanes: from chords that rule almost nothing out (large
    # coefficients) to chords that rule out almost everything
    rng = np.random.default_rng(int(amp * 1e6) + block)
    tab = _table("d4_discrete")
    lanes = L.candidate_lanes(tab, tab.side_w, BIG)
    E = len(tab.sides[tab.side_w]["g"])
    g = rng.normal(0, 1e-3, E)
    A = rng.normal(0, amp, (E, 3)) + 1j * rng.normal(0, amp, (E, 3))
    lanes[2] = -1  # a class without lanes: no contact there
    i = np.arange(3, 3 + 37 * tab.N)
    plan = L.LanePlan(tab, lanes, i, block)
    for p in (None, plan):
        val, first = L.lane_minimum(tab, lanes, g, A, i, block=block, plan=p)
        w = _waves(tab, i)
        for k in range(len(i)):
            e = lanes[i[k] % tab.N]
            e = e[e >= 0]
            if not e.size:
                assert val[k] == np.inf and first[k] == -1
                continue
            v = g[e] + (A[e] @ w[k]).real
            assert val[k] == pytest.approx(v.min(), abs=1e-15)
            assert first[k] in e and g[first[k]] + (A[first[k]] @ w[k]).real == pytest.approx(v.min(), abs=1e-15)


def test_a_lane_plan_keeps_the_waves_of_a_stretch_for_the_next_drive():
    tab = _table("d4_discrete")
    lanes = L.candidate_lanes(tab, tab.side_w, BIG)
    i = np.arange(0, 9 * tab.N)
    a = L.LanePlan(tab, lanes, i)
    b = L.LanePlan(tab, lanes, i)
    assert all(x[3] is y[3] for x, y in zip(a.classes, b.classes))  # the same arrays, not built again
    c = L.LanePlan(tab, lanes, i[::-1])  # not a stretch: built, not kept
    assert all(x[3] is not y[3] for x, y in zip(a.classes, c.classes))
    for _ in range(L._WAVE_CACHE + 1):
        i = i + tab.N * 9
        L.LanePlan(tab, lanes, i)
    assert len(tab.__dict__["_wave_cache"]) == L._WAVE_CACHE


def test_fold_angle_wraps_into_the_half_open_turn():
    x = np.concatenate([np.linspace(-40, 40, 2001), [math.pi, -math.pi, 3 * math.pi, 0.0]])
    y = L.fold_angle(x)
    assert np.all((y >= -math.pi) & (y < math.pi))
    turns = (x - y) / (2 * math.pi)
    np.testing.assert_allclose(turns, np.round(turns), rtol=0, atol=1e-12)
    assert L.fold_angle(math.pi) == -math.pi and L.fold_angle(0.5) == 0.5


@pytest.mark.parametrize("lever", ["rigid", "flex"])
@pytest.mark.parametrize("name", NAMES)
def test_the_installation_angle_scan_is_the_ke_at_each_angle(name, lever):
    # D2 engages on both flanks in part of the turn (the non-working side's first contact counts there) and its
    # record (80 800 samples) takes two passes of the scan; D4 interferes throughout
    tab = _table(name)
    key = "rigid_install" if lever == "rigid" else "flex_install"
    angles = [0.0, 0.7, 2.9, 4.4, 6.0]
    pp = K.install_angle_scan(tab, BIG, angles, lever)
    ref = [K.kinematic_error(_drive(name), BIG.replace(**{key: a}), table=tab).ke_pp for a in angles]
    np.testing.assert_allclose(pp, ref, rtol=1e-12, atol=0)
    assert np.ptp(pp) * AS > 1.0  # the angle matters (arcseconds)
    with pytest.raises(DesignError, match=r"^lever: must be rigid or flex, got 'cam'$"):
        K.install_angle_scan(tab, BIG, angles, "cam")


def test_the_optimum_installation_angle_is_no_worse_than_any_grid_angle():
    tab = _table("d4_discrete")
    best, best_pp, grid, pp = K.optimize_install_angle(tab, BIG, n_grid=12)
    np.testing.assert_allclose(grid, 2 * math.pi * np.arange(12) / 12, rtol=0, atol=1e-15)
    np.testing.assert_allclose(pp, K.install_angle_scan(tab, BIG, grid), rtol=1e-12, atol=0)
    assert 0.0 <= best < 2 * math.pi
    ke_at = lambda a: K.kinematic_error(_drive("d4_discrete"), BIG.replace(rigid_install=a), table=tab).ke_pp  # noqa: E731
    assert ke_at(best) == pytest.approx(best_pp, rel=1e-12)
    brute = np.array([ke_at(a) for a in np.radians(np.arange(0.0, 360.0, 7.5))])
    assert best_pp <= brute.min() + 1e-15
    assert best_pp < pp.min()  # the refinement improves on the coarse grid here


def test_the_spectrum_of_a_planted_wave():
    I = 4000
    t = np.arange(I) / I
    ke = 3e-5 * np.cos(2 * math.pi * 7 * t + 0.4) + 1e-5 * np.sin(2 * math.pi * 40 * t) + 2e-4
    for turns, u in ((100.0, 100.0), (50.0, 100.0)):  # one flexspline turn, half a turn
        res = K.KEResult(t, t, t, t, ke, 16, turns, "mixed", u)
        orders, amp = K.spectrum(res)
        per = u / turns  # orders per flexspline turn of one cycle per record
        assert len(orders) == I // 2 + 1
        np.testing.assert_allclose(orders, per * np.arange(I // 2 + 1), rtol=1e-15)
        assert amp[7] == pytest.approx(3e-5, rel=1e-12) and amp[40] == pytest.approx(1e-5, rel=1e-12)
        assert amp[0] < 1e-18  # the mean is removed
        assert np.delete(amp, [7, 40]).max() < 1e-18


def test_the_expected_orders_are_the_closed_forms():
    assert K.expected_orders(200, 202) == {
        "rigid": 100.0,
        "flex": 101.0,
        "rigid x2": 200.0,
        "flex x2": 202.0,
        "mesh": 20200.0,
    }
    assert K.expected_orders(86, 88) == {"rigid": 43.0, "flex": 44.0, "rigid x2": 86.0, "flex x2": 88.0, "mesh": 3784.0}


def test_a_table_for_another_cam_borne_offset_is_refused():
    tab = _table("d4_discrete")
    for change in ({"cam_cam": 0.001}, {"cam_cam_phase": 0.3}):
        with pytest.raises(DesignError) as err:
            K.kinematic_error(_drive("d4_discrete"), BIG.replace(**change), table=tab, samples=10)
        assert str(err.value) == (
            "imperfections.cam_offset_cam_um: the contact table was built for another cam-borne offset"
        )


@pytest.mark.parametrize("which", ["working", "non-working"])
def test_a_side_without_contacts_is_refused(which):
    tab = _table("d4_discrete")
    side = tab.side_w if which == "working" else -tab.side_w
    tab.sides = {**tab.sides, side: {k: v[:0] for k, v in tab.sides[side].items()}}
    want = (
        f"no tooth of the flexspline comes within reach of a rigid tooth on its {which} side at any generator "
        "angle: the output is not driven and has no KE; check the tooth heights, the shifts and W0 (wgcad audit)"
    )
    for run in (
        lambda t: K.kinematic_error(_drive("d4_discrete"), BIG, table=t, samples=10),
        lambda t: K.install_angle_scan(t, BIG, [0.0]),
    ):
        with pytest.raises(ModelError) as err:
            run(_copy_sides(tab))
        assert str(err.value) == want


@pytest.mark.parametrize("which", ["working", "non-working"])
def test_samples_without_a_contact_are_counted_and_refused(which):
    # one side's contacts of one class removed: its samples turn freely
    tab = _table("d4_discrete")
    side = tab.side_w if which == "working" else -tab.side_w
    S = tab.sides[side]
    keep = S["m"] % tab.N != 3
    tab.sides = {**tab.sides, side: {k: v[keep] for k, v in S.items()}}
    I = 10 * tab.N + 3
    free = int(np.count_nonzero(_class_of(tab, np.arange(I)) == 3))
    with pytest.raises(ModelError) as err:
        K.kinematic_error(_drive("d4_discrete"), BIG, table=_copy_sides(tab), samples=I)
    assert str(err.value) == (
        f"the flexspline turns freely at {free} of {I} generator angles (no tooth within reach of a rigid tooth "
        "on one side): the output is not driven there and has no KE; check the tooth heights and W0 (wgcad audit)"
    )
    # no sample at all: nothing to refuse, an empty record
    res = K.kinematic_error(_drive("d4_discrete"), BIG, table=_copy_sides(tab), samples=0)
    assert len(res.ke) == 0 and res.deep_overlap_fraction == 0.0 and res.engagement == "none (no samples)"


def test_without_a_table_the_ke_builds_its_own():
    d = _drive("d4_discrete")
    imp = _scaled(BIG, 0.5)
    own = K.kinematic_error(d, imp, n_per_mesh=4, samples=700)
    given = K.kinematic_error(d, imp, table=K.contact_table(d, imp, 4), samples=700)
    np.testing.assert_array_equal(own.ke, given.ke)
    assert own.n_per_mesh == 4
    # on the coned D2 its own table reads the audit's three sections, or the sections asked for
    d2 = _drive("d2_imperfect")
    far = [float(d2.sections(3)[-1])]  # the closed end alone (the open end is where the first contacts are)
    for asked, used in ((None, list(d2.sections(3))), (far, far)):
        own = K.kinematic_error(d2, imp, n_per_mesh=2, sections=asked, samples=500)
        given = K.kinematic_error(d2, imp, table=K.contact_table(d2, imp, 2, sections=used), samples=500)
        np.testing.assert_array_equal(own.ke, given.ke)


def test_a_deep_first_contact_is_flagged_only_where_it_is_first():
    # the two lowest contacts of a class set just either side of the trusted depth: the errors take turns at
    # putting each first, and only the samples where the deep one is first count
    tab = _table("d2_imperfect")
    S = dict(tab.sides[tab.side_w])
    g = S["g"].copy()
    c = 1
    e = np.nonzero(S["m"] % tab.N == c)[0]
    p, q = e[np.argsort(g[e])[:2]]
    g[p], g[q] = -K.DEEP_OVERLAP - 2e-6, -K.DEEP_OVERLAP + 2e-6
    S["g"] = g
    tab.sides = {**tab.sides, tab.side_w: S}
    I = 40 * tab.N * tab.z_b
    _, arg = _brute(tab, tab.side_w, BIG, np.arange(I))
    deep = (arg >= 0) & (g[np.maximum(arg, 0)] < -K.DEEP_OVERLAP)
    assert 0.0 < deep.mean() < 1.0 / tab.N  # the deep one is first in part of its class only
    for reference in (False, True):
        res = K.kinematic_error(_drive("d2_imperfect"), BIG, table=_copy_sides(tab), samples=I, reference=reference)
        assert res.deep_overlap_fraction == pytest.approx(deep.mean(), abs=1e-15)


@pytest.mark.parametrize(
    "imp",
    [
        Imperfections(rigid_runout=3e-3, rigid_runout_phase=0.4, rigid_install=1.0),
        Imperfections(flex_runout=3e-3, flex_runout_phase=1.1, flex_install=-0.5),
        Imperfections(rigid_ecc=2e-3, rigid_ecc_phase=0.5),
        Imperfections(flex_ecc=2e-3, flex_ecc_phase=2.0),
        Imperfections(cam_fixed=2e-3, cam_fixed_phase=0.7, cam_flex=2e-3, cam_flex_phase=-1.0),
    ],
    ids=["rigid_runout", "flex_runout", "rigid_ecc", "flex_ecc", "cam"],
)
def test_the_linear_ke_is_the_exact_poses_ke(imp):
    # the table's linear error terms against exact poses of every tooth and a fresh contact search (no table):
    # errors of 2-3 um, a second-order residual of (e / r)^2 rotations times the lever, far below 0.05''
    d = _drive("d4_discrete")
    tab = _table("d4_discrete")
    res = K.kinematic_error(d, imp, table=tab, samples=2000)
    for i in (0, 613, 1999):
        for side, arr in ((tab.side_w, res.delta_w), (-tab.side_w, res.delta_n)):
            exact = K.closing_direct(d, imp, res.phi_h[i], side)
            assert abs(arr[i] - exact) * AS < 0.05, (i, side, arr[i] * AS, exact * AS)
    # and the errors move the KE (well above the tolerance)
    perfect = K.kinematic_error(d, Imperfections(), table=tab, samples=2000)
    assert np.abs(res.delta_w - perfect.delta_w).max() * AS > 1.0


def _basins(step):
    """A curve of the largest KE against the angle with four basins (grid index + offset in grid steps, true
    minimum, value at the nearest grid angle): by their grid values the three best are A, B, C, and C is the
    deepest of those; D is deeper still but its grid value is the worst; A's neighbours lie close above it."""
    spec = [(0.95, 1.0, None), (5.3, 0.9, 1.1), (13.37, 0.5, 2.2), (9.2, 0.2, 2.3)]
    out = []
    for pos, low, at_grid in spec:
        off = (pos - round(pos)) * step
        out.append((pos * step, low, 0.02 if at_grid is None else (at_grid - low) / off**2))

    def curve(angles):
        a = np.atleast_1d(np.asarray(angles, dtype=float))
        v = np.full(a.shape, 3.0)
        for x0, low, c in out:
            dx = L.fold_angle(a - x0)
            v = np.minimum(v, np.where(np.abs(dx) < 1.5 * step, low + c * dx**2, np.inf))
        return v

    return curve


def test_the_optimiser_refines_the_three_best_local_minima_of_its_grid(monkeypatch):
    # docs: a grid of n_grid angles, then grids of 1/10 and 1/100 of its step around the three best local minima.
    # On the curve above that finds C's minimum exactly (13.37 steps lies on the last grid), not A's or B's
    # (shallower) nor D's (deeper, but its grid value is the fourth)
    n = 18
    step = 2 * math.pi / n
    curve = _basins(step)
    levers = []

    def scan(tab, imp, angles, lever="rigid"):
        levers.append(lever)
        return curve(angles)

    monkeypatch.setattr(K, "install_angle_scan", scan)
    for lever in ("rigid", "flex"):
        best, best_pp, grid, pp = K.optimize_install_angle(None, None, lever=lever, n_grid=n)
        assert best == pytest.approx(13.37 * step, abs=1e-9) and best_pp == pytest.approx(0.5, abs=1e-12)
        np.testing.assert_array_equal(pp, curve(grid))
        assert set(levers) == {lever}
        levers.clear()
    # the default grid is 36 angles (10 deg)
    assert len(K.optimize_install_angle(None, None)[2]) == 36


@pytest.mark.parametrize("wave", range(3))
def test_lane_minimum_keeps_a_lane_that_dips_below_another_between_a_block_s_ends(wave):
    # per class a flat lane (g = 0), a lane far above it, and one of a single wave of amplitude a: where the wave's
    # lane lies above the flat one at both ends of a block but dips below it between them (by up to
    # a (1 - cos(theta / 2)) below its chord, theta the wave's turn over the block), only the bound on that dip keeps
    # it (a block evaluates as many lanes as the busiest block keeps, the far lane filling in first); drawn at
    # random offsets and phases, hundreds of blocks sit at that edge
    rng = np.random.default_rng(100 + wave)
    tab = _table("d4_discrete")
    N, a = tab.N, 1e-3
    lanes = np.arange(3 * N).reshape(N, 3)
    i = np.arange(0, 64 * 16 * N)
    plan = L.LanePlan(tab, lanes, i)
    w = _waves(tab, i)[:, wave]
    r = i % N
    for _ in range(40):
        g = np.zeros(3 * N)
        g[1::3] = 10 * a
        g[2::3] = rng.uniform(0.5 * a, 1.1 * a, N)
        A = np.zeros((3 * N, 3), dtype=complex)
        A[2::3, wave] = a * np.exp(1j * rng.uniform(-np.pi, np.pi, N))
        val, _ = L.lane_minimum(tab, lanes, g, A, i, plan=plan)
        ref = np.minimum(0.0, g[3 * r + 2] + (A[3 * r + 2, wave] * w).real)
        np.testing.assert_allclose(val, ref, rtol=0, atol=SAME)


def test_the_class_waves_kept_with_a_table_are_the_last_two_records():
    # a sweep's drives share one table: the waves of the last two record lengths are kept, the oldest dropped
    tab = _table("d4_discrete")
    for I in (100, 200, 300):
        a = L.class_waves(tab, I)
        assert a is L.class_waves(tab, I)  # kept, not built again
        w = _waves(tab, np.arange(I))
        for r in range(tab.N):
            np.testing.assert_allclose(a[r][:3].T, w[r :: tab.N].real, rtol=0, atol=1e-15)
            np.testing.assert_allclose(a[r][3:6].T, -w[r :: tab.N].imag, rtol=0, atol=1e-15)
            assert np.all(a[r][6] == 1.0)
    assert sorted(tab.__dict__["_class_waves"]) == [200, 300]
