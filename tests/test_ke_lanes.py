"""The first contact of every sample by dominance (accuracy/ke_lanes.py): the same lanes, the same minimum and the same KE as the block-by-block search and as every lane at every sample."""

import math

import numpy as np
import pytest
from conftest import TEMPLATES
from test_ke import ALL_ERRORS as KE_ALL_ERRORS

from wgcad.accuracy import ke as K
from wgcad.accuracy import ke_lanes as L
from wgcad.design import load_design
from wgcad.design.schema import parse_design
from wgcad.drive import build_drive
from wgcad.placement.imperfect import Imperfections
from wgcad.sweep.sampling import sample_design_data, sample_values
from wgcad.sweep.spec import load_spec

AS = 180.0 / math.pi * 3600.0
DESIGNS = TEMPLATES.parent / "tests" / "designs"
#: rad: the two paths evaluate the same contact's ``g + Re(A . w)`` (a six-term dot product of ~1e-3 rad terms,
#: rounding ~1e-19 rad) and differ only in how the product is summed; a contact missed or wrongly kept shows as
#: the gap between two contacts' lines. Measured: identical to the bit on the reference machine.
SAME = 1e-15

#: every error kind at once (the set tests/test_ke.py checks the KE with)
ALL_ERRORS = KE_ALL_ERRORS


@pytest.fixture(scope="module")
def d4_all():
    drive = build_drive(load_design(TEMPLATES / "d4_discrete.toml"))
    imp = Imperfections(**ALL_ERRORS)
    return drive, imp, K.contact_table(drive, imp)


@pytest.fixture(scope="module")
def d2_sweep():
    """The bundled D2 tolerance Monte Carlo as a worker sees it: the shared table (the sweep's largest amplitudes)
    and the imperfections of its first samples."""
    from wgcad.sweep import tasks

    pl = load_spec(TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml").payload()
    tasks.clear_cache()
    assert tasks.run_sample(pl, 0)["status"] == "ok"
    [tab] = tasks._CACHE["table"].values()
    [drive] = tasks._CACHE["drive"].values()
    imps = []
    for i in range(50):
        d = parse_design(sample_design_data(pl["design"], pl["parameters"], sample_values(pl, i)))
        imps.append(Imperfections.from_spec(d.imperfections))
    tasks.clear_cache()
    return drive, tab, imps


def _loop_lanes(tab, side, imp, slack=1.05):
    """candidate_lanes as first written: class by class, group by group (the reference of the one-pass form)."""
    S = tab.sides[side]
    z_g, z_b, N = tab.z_g, tab.z_b, tab.N
    ntn = np.hypot(S["nt"][:, 0], S["nt"][:, 1])
    A_b = 0.5 * imp.rigid_runout / tab.r_b
    A_a = (0.5 * imp.flex_runout + imp.flex_ecc) / tab.r_g
    Vmax = imp.rigid_ecc + S["c"] * (imp.cam_flex + imp.cam_fixed)
    B = Vmax * ntn + A_b * np.abs(S["a_beta"]) + A_a * np.abs(S["a_phi"]) + imp.flex_ecc * np.abs(S["a_rho"])
    B = B * slack + 1e-12
    M = z_g * N
    phi = L.fold_angle(2 * math.pi * S["m"] / M)
    zone = np.where(np.abs(phi) <= 0.5 * math.pi, 0, 1)
    cls = (-tab.sigma * np.arange(N)) % N
    mf = (S["m"] + M // 2) % M - M // 2
    cq = np.round(S["c"] * 1e6).astype(int)
    group = np.unique(np.stack([zone, cq], 1), axis=0, return_inverse=True)[1].ravel()
    out = []
    for r in range(N):
        e = np.nonzero(S["m"] % N == cls[r])[0]
        if e.size == 0:
            out.append(e)
            continue
        keep = S["g"][e] - B[e] <= np.min(S["g"][e] + B[e])
        for gk in np.unique(group[e]):
            sel = group[e] == gk
            grp = e[sel]
            es = grp[np.argmin(S["g"][grp])]
            dk = np.abs(mf[grp] - mf[es]) // N
            dj = np.abs(((S["j"][grp] - S["j"][es] + (mf[grp] - mf[es]) // N) + z_b // 2) % z_b - z_b // 2)
            dnt = np.hypot(*(S["nt"][grp] - S["nt"][es]).T)
            D = (
                Vmax[grp] * (dnt + ntn[es] * 2 * math.pi * dk / z_b)
                + A_b * (np.abs(S["a_beta"][grp] - S["a_beta"][es]) + np.abs(S["a_beta"][es]) * 2 * math.pi * dj / z_b)
                + A_a * (np.abs(S["a_phi"][grp] - S["a_phi"][es]) + np.abs(S["a_phi"][es]) * 2 * math.pi * dk / z_g)
                + imp.flex_ecc
                * (np.abs(S["a_rho"][grp] - S["a_rho"][es]) + np.abs(S["a_rho"][es]) * 2 * math.pi * dk / z_g)
            )
            far = S["g"][grp] - S["g"][es] > slack * D + 1e-12
            keep[np.nonzero(sel)[0][far]] = False
        out.append(e[keep])
    lanes = np.full((N, max(max(len(x) for x in out), 1)), -1, dtype=int)
    for r, x in enumerate(out):
        lanes[r, : len(x)] = x
    return lanes


def test_candidate_lanes_in_one_pass_are_the_loops(d4_all, d2_sweep):
    # the bounds are the same sums of the amplitudes times per-contact factors, kept with the table: the same
    # lanes in the same order, for errors of every kind, the sweep's samples and the table's own slack of 2
    drive, imp, tab = d4_all
    cases = [(tab, imp), (tab, Imperfections(rigid_runout=0.02)), (tab, Imperfections())]
    cases += [(d2_sweep[1], x) for x in d2_sweep[2][:10]]
    for t, x in cases:
        for side in t.sides:
            for slack in (1.05, 2.0):
                np.testing.assert_array_equal(L.candidate_lanes(t, side, x, slack), _loop_lanes(t, side, x, slack))


def _every_lane(tab, side, imp, i):
    """``g + Re(A . w)`` of every candidate lane at samples ``i``, inf on padding, (I, C); and the lanes."""
    lanes = K.candidate_lanes(tab, side, imp)
    A = L.harmonics(tab, side, imp)
    g = tab.sides[side]["g"]
    e = lanes[i % tab.N]
    return np.where(e >= 0, g[np.maximum(e, 0)] + L.harmonic_terms(tab, lanes, A, i), np.inf), lanes, A, g


@pytest.mark.parametrize("which", ["d4", "d2"])
def test_undominated_lanes_hold_every_first_contact(which, d4_all, d2_sweep):
    # A lane that stays above another by more than their coefficients' difference is never first: the minimum over
    # the undominated lanes is the minimum over every lane, at every sample; and the test drops lanes (it is
    # exercised). D4 with every kind of error and installation angle, D2 with a sweep sample.
    tab, imp = (d4_all[2], d4_all[1]) if which == "d4" else (d2_sweep[1], d2_sweep[2][3])
    I = 3 * tab.N * tab.z_b + 5  # three generator turns and a few more: not a whole number of classes
    i = np.arange(I)
    for side in tab.sides:
        full, lanes, A, g = _every_lane(tab, side, imp, i)
        alive = L.undominated(lanes, A, g)
        # D2's classes hold 100-190 candidates, D4's three
        assert alive.sum() < (0.3 if which == "d2" else 0.9) * (lanes >= 0).sum()
        [(val, flagged)] = L.first_contacts(tab, [(lanes, g, A, np.ones(len(g), dtype=bool))], I)
        assert np.abs(val - full.min(axis=1)).max() < SAME and flagged.all()
        # every lane dropped really is above the one that dropped it at every sample: no lane below the minimum
        dropped = np.where(alive[i % tab.N], np.inf, full)
        assert np.all(dropped.min(axis=1) > val - SAME)


def test_first_contacts_flag_the_contact_that_is_first(d4_all):
    # flag names samples whose minimum is taken by a flagged contact (the deep-overlap fraction rests on it)
    drive, imp, tab = d4_all
    I = 2 * tab.N * tab.z_b
    i = np.arange(I)
    side = tab.side_w
    full, lanes, A, g = _every_lane(tab, side, imp, i)
    e = lanes[i % tab.N]
    first = np.take_along_axis(e, np.argmin(full, axis=1)[:, None], 1)[:, 0]
    flag = np.zeros(len(g), dtype=bool)
    flag[np.unique(first)[::2]] = True  # every other contact that is ever first
    [(_, flagged)] = L.first_contacts(tab, [(lanes, g, A, flag)], I)
    np.testing.assert_array_equal(flagged, flag[first])
    assert 0 < flagged.mean() < 1


def _same_ke(a, b):
    for key in ("delta_w", "delta_n", "lost_motion", "ke"):
        x, y = getattr(a, key), getattr(b, key)
        assert x.shape == y.shape and np.abs(x - y).max() < SAME, key
    assert abs(a.ke_pp - b.ke_pp) < SAME
    assert a.deep_overlap_fraction == b.deep_overlap_fraction and a.engagement == b.engagement


def test_the_bundled_d2_ke_equals_the_block_search():
    # wgcad ke templates/d2_imperfect.toml: the whole revolution (323 200 generator angles) and a shorter record
    design = load_design(TEMPLATES / "d2_imperfect.toml")
    drive = build_drive(design)
    imp = Imperfections.from_spec(design.imperfections)
    tab = K.contact_table(drive, imp)
    _same_ke(K.kinematic_error(drive, imp, table=tab), K.kinematic_error(drive, imp, table=tab, reference=True))
    for n in (7, 16 * 202 + 3):
        _same_ke(
            K.kinematic_error(drive, imp, table=tab, samples=n),
            K.kinematic_error(drive, imp, table=tab, samples=n, reference=True),
        )


def test_fifty_tolerance_samples_give_the_block_search_ke(d2_sweep):
    # the Monte Carlo's own computation (shared table, its seed's first 50 samples, whole revolutions): the KE of
    # every sample, its lost motion and the verdict against the 120'' limit are the block search's
    drive, tab, imps = d2_sweep
    pp = []
    for imp in imps:
        a = K.kinematic_error(drive, imp, table=tab)
        b = K.kinematic_error(drive, imp, table=tab, reference=True)
        _same_ke(a, b)
        assert (a.ke_pp * AS <= 120.0) == (b.ke_pp * AS <= 120.0)
        pp.append(a.ke_pp * AS)
    assert min(pp) < 120.0 < max(pp)  # both verdicts occur


def test_d4_with_every_error_equals_the_block_search(d4_all):
    # second features, the flexspline-borne cam offset (the third wave) and both installation angles
    drive, imp, tab = d4_all
    _same_ke(K.kinematic_error(drive, imp, table=tab), K.kinematic_error(drive, imp, table=tab, reference=True))


def test_deep_overlaps_are_counted_as_by_the_block_search():
    # D2 as first templated: at its open end every first contact overlaps deeply (fraction 1), mid-face none
    drive = build_drive(load_design(DESIGNS / "d2_imperfect_nominal.toml"))
    imp = Imperfections.from_spec(drive.design.imperfections)
    seen = set()
    for z in (0.0, 16.0, None):
        tab = K.contact_table(drive, imp, 8, sections=None if z is None else [z])
        a = K.kinematic_error(drive, imp, table=tab, samples=8 * 202 * 4)
        b = K.kinematic_error(drive, imp, table=tab, samples=8 * 202 * 4, reference=True)
        _same_ke(a, b)
        seen.add(a.deep_overlap_fraction)
    assert 1.0 in seen and 0.0 in seen
