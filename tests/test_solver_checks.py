"""The contact solver (wgcad.elastic.solve) against closed forms and against every active set tried in turn.

Written against the survivors of ``benchmarks/mutation.py --only solve``: the sprung freedoms (``A'F + k a = f``),
the held body (no freedom), the empty active set, the tolerance on forces and the pivoting rule had no test of
their own in tests/test_elastic_solver.py (tests/test_elastic_supports.py reaches them only through whole drives).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from wgcad.elastic.solve import ContactSolveError, solve_contact_qp, solve_supported

#: the refusal's whole message: the reason and what it means for the drive
REFUSAL = (
    r"^contact solver: the active contacts cannot balance the loads \(equilibrium residual \d\.\d\de[+-]\d+\); "
    r"no set of contacts can carry this torque$"
)


def enumerated(M, q, A, f, k):
    """The solution by trying every active set (small problems only): the one whose KKT system gives forces >= 0
    on it and gaps >= 0 off it (unique: the QP is strictly convex)."""
    m, r = A.shape
    for n in range(m + 1):
        for W in itertools.combinations(range(m), n):
            W = list(W)
            # [M_WW  -A_W] [F_W]   [-q_W]
            # [A_W'   K  ] [ a ] = [ f  ]
            top = np.hstack([M[np.ix_(W, W)], -A[W]])
            bot = np.hstack([A[W].T, np.diag(k)])
            lhs = np.vstack([top, bot])
            rhs = np.concatenate([-q[W], f])
            try:
                x = np.linalg.solve(lhs, rhs)
            except np.linalg.LinAlgError:
                continue
            F = np.zeros(m)
            F[W] = x[:n]
            a = x[n:]
            gap = q + M @ F - A @ a
            if np.all(F >= -1e-10) and np.all(np.delete(gap, W) >= -1e-10):
                return F, a
    raise AssertionError("no active set solves it")


def test_one_contact_on_a_free_body_carries_the_load():
    """A body pressed by P onto one contact of compliance c from an overlap g0 < 0: F = P, a = g0 + c P."""
    c, g0, P = 2e-4, -0.01, 300.0
    s = solve_contact_qp([[c]], [g0], [[1.0]], [P])
    assert s.F[0] == pytest.approx(P, rel=1e-14) and s.a[0] == pytest.approx(g0 + c * P, rel=1e-12)
    assert abs(s.gap[0]) < 1e-15 and s.equilibrium < 1e-14


def test_one_contact_on_a_sprung_body_shares_the_load_with_the_spring():
    """The same body on a spring k: F + k a = P and the gap closed, so F = (P - k g0) / (1 + k c)."""
    c, g0, P, k = 2e-4, -0.01, 300.0, 5e4
    s = solve_contact_qp([[c]], [g0], [[1.0]], [P], stiffness=[k])
    F = (P - k * g0) / (1.0 + k * c)
    assert s.F[0] == pytest.approx(F, rel=1e-13)
    assert s.a[0] == pytest.approx((P - F) / k, rel=1e-12)


def test_a_sprung_body_pulled_away_leaves_its_contacts_open():
    """No contact loaded (the empty active set): the body moves by P / k on its spring, every gap opens by it."""
    q = np.array([0.02, 0.05])
    s = solve_contact_qp(np.diag([1e-4, 2e-4]), q, [[1.0], [1.0]], [-100.0], stiffness=[1e4])
    np.testing.assert_array_equal(s.F, [0.0, 0.0])
    assert s.a[0] == pytest.approx(-0.01, rel=1e-14)
    np.testing.assert_allclose(s.gap, q + 0.01, rtol=1e-14)


def test_a_held_body_presses_each_overlap_by_its_own_compliance():
    """Every freedom held (no columns): each overlapping contact carries -g / c, the open one none."""
    q = np.array([-0.01, 0.03, -0.004])
    c = np.array([2e-4, 1e-4, 5e-4])
    s = solve_contact_qp(np.diag(c), q, np.zeros((3, 0)), np.zeros(0))
    np.testing.assert_allclose(s.F, [50.0, 0.0, 8.0], rtol=1e-13)
    assert s.a.shape == (0,)
    s2 = solve_supported(np.diag(c), q, np.ones((3, 1)), [123.0], [np.inf])
    np.testing.assert_allclose(s2.F, s.F, rtol=1e-13)
    np.testing.assert_array_equal(s2.a, [0.0])


@pytest.mark.parametrize("seed", [*range(12), 193])  # 10: once refused, 193: once cycled
def test_random_problems_equal_the_enumerated_active_sets(seed):
    """Random small problems (SPD compliance, overlaps and gaps, two bodies free or sprung, cold and warm starts)
    give the forces and displacements of the enumeration to 1e-9 relative."""
    rng = np.random.default_rng(seed)
    m = 7
    B = rng.normal(size=(m, m))
    M = (B @ B.T + m * np.eye(m)) * 1e-4
    q = rng.uniform(-0.02, 0.03, m)
    A = np.column_stack([np.ones(m), rng.uniform(-1, 1, m)])
    f = np.array([rng.uniform(50, 500), rng.uniform(-50, 50)])
    k = np.array([0.0, 0.0]) if seed % 2 == 0 else np.array([rng.uniform(1e3, 1e5), 0.0])
    F_ref, a_ref = enumerated(M, q, A, f, k)
    for active in (None, rng.random(m) < 0.5):
        s = solve_contact_qp(M, q, A, f, active=active, stiffness=k)
        scale = max(float(F_ref.max()), 1.0)
        np.testing.assert_allclose(s.F, F_ref, rtol=0, atol=1e-9 * scale)
        np.testing.assert_allclose(s.a, a_ref, rtol=1e-9, atol=1e-12)
        assert s.F.min() >= 0.0 and s.gap.min() >= -1e-12
        np.testing.assert_allclose(s.gap, q + M @ s.F - A @ s.a, rtol=0, atol=1e-14)
        assert s.complementarity < 1e-9 and s.equilibrium < 1e-12


def test_an_elastic_field_joins_the_compliance():
    """``field=(U, W)`` solves as the compliance M + U W U' given whole."""
    rng = np.random.default_rng(3)
    m = 6
    B = rng.normal(size=(m, m))
    M = (B @ B.T + m * np.eye(m)) * 1e-4
    U = rng.normal(size=(m, 2))
    W = np.array([[2e-5, 5e-6], [5e-6, 1e-5]])
    q = rng.uniform(-0.02, 0.02, m)
    A = np.ones((m, 1))
    a = solve_supported(M, q, A, [200.0], [0.0], field=(U, W))
    b = solve_supported(M + U @ W @ U.T, q, A, [200.0], [0.0])
    np.testing.assert_allclose(a.F, b.F, rtol=0, atol=1e-10 * b.F.max())


def test_a_load_no_contact_can_carry_is_refused():
    """A free freedom that no contact touches (its column all zero) cannot take a load: refused, not returned."""
    with pytest.raises(ContactSolveError, match=REFUSAL):
        solve_contact_qp(np.diag([1e-4, 1e-4]), [-0.01, -0.01], [[1.0, 0.0], [1.0, 0.0]], [100.0, 5.0])


def test_the_pivot_cap_is_reported():
    """A cap too small for the problem ends in one line naming it, never a half-solved state."""
    rng = np.random.default_rng(0)
    m = 7
    B = rng.normal(size=(m, m))
    M = (B @ B.T + m * np.eye(m)) * 1e-4
    with pytest.raises(ContactSolveError, match=r"no convergence in 1 pivots \(\d+ contacts still infeasible\)"):
        solve_contact_qp(M, rng.uniform(-0.02, 0.0, m), np.ones((m, 1)), [-5000.0], max_iter=1)


def _problem(seed):
    """A random small problem whose block pivots stall, so that Murty's single pivots finish it (the seeds below
    were found by tracing the solver over 4,000 of these: each takes at least one single pivot)."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(5, 10))
    B = rng.normal(size=(m, m))
    M = (B @ B.T + 0.05 * m * np.eye(m)) * 1e-4
    q = rng.uniform(-0.02, 0.03, m)
    A = np.column_stack([np.ones(m), rng.uniform(-1, 1, m)])
    f = np.array([rng.uniform(50, 500), rng.uniform(-50, 50)])
    k = np.array([0.0, 0.0]) if seed % 2 == 0 else np.array([rng.uniform(1e3, 1e5), 0.0])
    return M, q, A, f, k, rng.random(m) < 0.5


@pytest.mark.parametrize("seed", [1746, 2102, 2556, 2694, 3848])
def test_problems_the_single_pivots_finish_equal_the_enumeration(seed):
    """Where the block pivots stop reducing the infeasible contacts, the anti-cycling single pivots take over: the
    same forces and displacements as trying every active set."""
    M, q, A, f, k, active = _problem(seed)
    F_ref, a_ref = enumerated(M, q, A, f, k)
    s = solve_contact_qp(M, q, A, f, active=active, stiffness=k)
    np.testing.assert_allclose(s.F, F_ref, rtol=0, atol=1e-9 * max(float(F_ref.max()), 1.0))
    np.testing.assert_allclose(s.a, a_ref, rtol=1e-9, atol=1e-12)


def test_a_soft_spring_and_a_free_body_with_every_contact_open():
    """No contact loaded: a sprung freedom moves by its load over its stiffness, however soft (0.5 N/mm), and a free
    freedom with no load stays where the least-norm answer puts it (0); the equilibrium is judged against the
    load itself (no contact force to compare with), and holds."""
    M = np.diag([1e-4, 2e-4, 3e-4])
    q = np.array([5.0, 6.0, 7.0])  # far open: 10 N on 0.5 N/mm moves the body 20 mm, still short of every contact
    A = np.array([[0.0, 0.1], [0.0, 0.1], [0.0, 0.1]])
    s = solve_contact_qp(M, q, A, [0.0, 10.0], stiffness=[0.0, 0.5])
    np.testing.assert_array_equal(s.F, 0.0)
    np.testing.assert_allclose(s.a, [0.0, 20.0], rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(s.gap, q - 2.0, rtol=1e-14)
    assert s.equilibrium < 1e-14
    # a spring whose k (f / k) rounds off f by 3.6e-15: judged against the load, that is no residual
    k, f = 0.5348999931723383, 18.766376051967598
    s = solve_contact_qp(M, q * 10, A, [0.0, f], stiffness=[0.0, k])
    assert s.a[1] == pytest.approx(f / k, rel=1e-15) and 0 < s.equilibrium < 1e-15


def test_a_preload_with_no_outside_load_balances_on_its_own_forces():
    """A free body squeezed between two overlapping contacts and no outside load: the contacts' forces balance
    each other, and the equilibrium is judged against them (the load is zero), not refused."""
    c = 1e-4
    s = solve_contact_qp(np.diag([c, c]), [-0.01, -0.01], [[1.0], [-1.0]], [0.0])
    np.testing.assert_allclose(s.F, [100.0, 100.0], rtol=1e-12)
    assert s.a[0] == pytest.approx(0.0, abs=1e-15)
    assert s.equilibrium < 1e-12
    # unequal contacts, whose forces balance only to rounding (6.5e-15 N of 77 N): a residual against the forces
    A = np.array([[1.0], [-0.7]])
    s = solve_contact_qp(np.diag([1e-4, 3e-4]), [-0.01, -0.02], A, [0.0])
    assert s.F[0] == pytest.approx(0.7 * s.F[1], rel=1e-13) and s.F[1] > 70.0
    assert 0 < s.equilibrium < 1e-15


def test_a_load_no_contact_can_carry_is_refused_at_any_scale():
    """The refusal is of a load no contact can carry, whatever its size: 1e-10 N as 100 N."""
    for P in (100.0, 1e-10):
        with pytest.raises(ContactSolveError, match=REFUSAL):
            solve_contact_qp(np.diag([1e-4, 1e-4]), [-0.01, -0.01], [[1.0, 0.0], [1.0, 0.0]], [P, P])


def test_no_contact_at_all():
    """A problem with no contact: a sprung body moves by its load over its stiffness, the figures are zero."""
    s = solve_contact_qp(np.zeros((0, 0)), np.zeros(0), np.zeros((0, 1)), [3.0], stiffness=[2.0])
    assert s.F.shape == (0,) and s.a[0] == pytest.approx(1.5, rel=1e-15)
    assert s.complementarity == 0.0 and s.equilibrium == 0.0 and s.iterations == 1


def test_block_pivots_take_few_steps_on_large_problems():
    """Judice and Pires' block pivots change every infeasible contact at once: a cold start of 40 to 130 contacts
    (random SPD compliance, overlaps and gaps, a free body) needs a handful of pivots (2-4 measured), where single
    pivots would need about one per loaded contact (40-125), and more contacts than the base pivot cap's 500 / 4
    are solved (the cap grows with them)."""
    rng = np.random.default_rng(5)
    for m in (40, 60, 130):
        B = rng.normal(size=(m, m))
        M = (B @ B.T + m * np.eye(m)) * 1e-4
        q = rng.uniform(-0.02, 0.03, m)
        A = np.column_stack([np.ones(m), rng.uniform(-1, 1, m)])
        s = solve_contact_qp(M, q, A, [300.0, 20.0])
        assert s.iterations <= 8 < int((s.F > 0).sum())
        assert s.gap.min() >= -1e-12 and s.equilibrium < 1e-12


class _Columns:
    """A compliance seen only through columns (as the elastic model's :class:`~wgcad.elastic.tables.Compliance`)."""

    def __init__(self, M):
        self._M = np.asarray(M, dtype=float)
        self.diag = np.diag(self._M).copy()
        self.shape = self._M.shape

    def cols(self, W):
        return self._M[:, W]

    def with_field(self, U, W):
        return _Columns(self._M + U @ W @ U.T)


def test_the_reported_figures_are_as_documented():
    """``iterations`` counts the systems solved (one from the right active set given), ``complementarity`` is
    ``max |F gap| / (max F max |q|)`` and ``equilibrium`` ``|A'F + K a - f| / max(|A_j| F_j, |f|)``."""
    rng = np.random.default_rng(4)
    m = 7
    B = rng.normal(size=(m, m))
    M = (B @ B.T + m * np.eye(m)) * 1e-4
    q = rng.uniform(-0.02, 0.03, m)
    A = np.column_stack([np.ones(m), rng.uniform(-1, 1, m)])
    f = np.array([300.0, 20.0])
    cold = solve_contact_qp(M, q, A, f)
    warm = solve_contact_qp(M, q, A, f, active=cold.F > 0)
    assert warm.iterations == 1 and cold.iterations >= 1
    np.testing.assert_allclose(warm.F, cold.F, rtol=0, atol=1e-10 * cold.F.max())
    for s in (cold, warm):
        comp = np.abs(s.F * s.gap).max() / (s.F.max() * np.abs(q).max())
        assert s.complementarity == pytest.approx(comp, rel=1e-12, abs=1e-300)
        eq = np.abs(A.T @ s.F - f).max() / max(np.abs(A * s.F[:, None]).max(), np.abs(f).max())
        assert s.equilibrium == pytest.approx(eq, rel=1e-9, abs=1e-18)


def test_supported_freedoms_free_sprung_and_held_equal_the_enumeration():
    """``solve_supported`` with one freedom free, one sprung and one held: the held one dropped (its displacement
    reported 0), the others as :func:`solve_contact_qp` with the two, checked by enumeration."""
    rng = np.random.default_rng(8)
    m = 6
    B = rng.normal(size=(m, m))
    M = (B @ B.T + m * np.eye(m)) * 1e-4
    q = rng.uniform(-0.02, 0.02, m)
    A = np.column_stack([np.ones(m), rng.uniform(-1, 1, m), rng.uniform(-1, 1, m)])
    f = np.array([250.0, -30.0, 1e6])  # the held freedom's load goes to its support
    k = np.array([0.0, 2e4, np.inf])
    s = solve_supported(M, q, A, f, k)
    F_ref, a_ref = enumerated(M, q, A[:, :2], f[:2], k[:2])
    np.testing.assert_allclose(s.F, F_ref, rtol=0, atol=1e-9 * F_ref.max())
    np.testing.assert_allclose(s.a[:2], a_ref, rtol=1e-9, atol=1e-12)
    assert s.a[2] == 0.0 and len(s.a) == 3
    # the compliance given by columns only, with a field joined: the same as the dense matrix with it
    U = rng.normal(size=(m, 1))
    Wf = np.array([[3e-5]])
    by_cols = solve_supported(_Columns(M), q, A, f, k, field=(U, Wf))
    dense = solve_supported(M + U @ Wf @ U.T, q, A, f, k)
    np.testing.assert_allclose(by_cols.F, dense.F, rtol=0, atol=1e-10 * dense.F.max())
    # a warm start from the solution's own contacts is taken: one system solved
    warm = solve_supported(M, q, A, f, k, active=s.F > 0)
    assert warm.iterations == 1
    np.testing.assert_allclose(warm.F, s.F, rtol=0, atol=1e-10 * s.F.max())


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_the_least_norm_solve_from_a_cold_workspace_cache_is_lstsq_s(n, monkeypatch):
    """``_least_norm`` asks LAPACK for its workspace once per system size and keeps it; a process's first solve of
    each size (and mutmut's forks, which inherit a filled cache) must give ``numpy.linalg.lstsq``'s least-norm
    solution with the same ``rcond``, for full-rank and rank-deficient systems, cold and warm."""
    import wgcad.elastic.solve as S

    monkeypatch.setattr(S, "_GELSD_WORK", {})
    rng = np.random.default_rng(n)
    B = rng.normal(size=(n, n))
    full = B @ B.T + n * np.eye(n)
    deficient = full.copy()
    if n > 1:  # a free body the active contacts cannot hold: one direction without stiffness
        u = rng.normal(size=n)
        u /= np.linalg.norm(u)
        P = np.eye(n) - np.outer(u, u)
        deficient = P @ full @ P
    for sys_ in (full, deficient, full):  # the first call fills the cache, the later ones read it
        rhs = rng.normal(size=n)
        want = np.linalg.lstsq(sys_, rhs, rcond=1e-12)[0]
        got = S._least_norm(sys_, rhs)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.abs(want).max())
    assert list(S._GELSD_WORK) == [n]
    # the rank decision at 1e-12 of the largest singular value: one at 1e-14 is dropped (LAPACK's default, machine
    # precision - also what it takes for any rcond >= 1 - would keep it and give a solution 1e14 long)
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    sv = np.logspace(0, -3, n)
    sv[-1] = 1e-14 if n > 1 else 1.0
    near = Q @ np.diag(sv) @ Q.T
    rhs = rng.normal(size=n)
    want = np.linalg.lstsq(near, rhs, rcond=1e-12)[0]
    np.testing.assert_allclose(S._least_norm(near, rhs), want, rtol=1e-8, atol=1e-10 * np.abs(want).max())
    assert np.abs(want).max() < 1e4


def test_integer_inputs_give_the_float_inputs_solution():
    """Overlaps, directions, loads and stiffnesses given as integers (a user's plain lists): the same solution."""
    M = np.array([[2, 1, 0], [1, 3, 1], [0, 1, 2]])
    q = np.array([-1, -2, 9])
    A = np.array([[1, 0], [1, 1], [1, -1]])
    f = np.array([3, 1])
    k = np.array([0, 2])
    ref = solve_contact_qp(M.astype(float), q.astype(float), A.astype(float), f.astype(float), stiffness=k * 1.0)
    got = solve_contact_qp(M, q, A, f, stiffness=k)
    np.testing.assert_allclose(got.F, ref.F, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(got.a, ref.a, rtol=1e-14, atol=1e-14)
    sup = solve_supported(M, q, A, f, k)
    np.testing.assert_allclose(sup.F, ref.F, rtol=1e-12, atol=1e-12)
    assert ref.F.max() > 0 and (ref.F == 0).any()  # contacts both carrying and open


def test_a_compliance_that_is_not_positive_definite_is_refused_by_name():
    """``M`` must be positive definite (ring compliance plus positive contact compliances); one that is not is
    refused with LAPACK's pivot named, not solved into negative energies."""
    M = np.array([[1.0, 2.0], [2.0, 1.0]])  # eigenvalues 3 and -1
    with pytest.raises(
        np.linalg.LinAlgError, match=r"^the active contacts' compliance is not positive definite \(potrf 2\)$"
    ):
        solve_contact_qp(M, [-1.0, -1.0], [[1.0], [1.0]], [1.0])
