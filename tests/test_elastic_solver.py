"""The contact solver (wgcad.elastic.solve): exact mixed LCP solutions checked by enumeration."""

import itertools

import numpy as np
import pytest

from wgcad.elastic.solve import ContactSolveError, solve_contact_qp


def _random_problem(rng, m, r=3):
    X = rng.normal(size=(m, m))
    M = X @ X.T / m + 0.05 * np.eye(m)
    q = rng.normal(size=m)
    A = rng.normal(size=(m, r))
    F0 = np.abs(rng.normal(size=m)) * (rng.random(m) < 0.5)
    return M, q, A, A.T @ F0  # f reachable with F >= 0


def _enumerate(M, q, A, f):
    """Every active set, solved directly: the unique one meeting all conditions (an independent reference)."""
    m = len(q)
    found = []
    for k in range(m + 1):
        for W in itertools.combinations(range(m), k):
            W = list(W)
            r = A.shape[1]
            K = np.block([[M[np.ix_(W, W)], -A[W]], [A[W].T, np.zeros((r, r))]])
            try:
                sol = np.linalg.solve(K, np.concatenate([-q[W], f]))
            except np.linalg.LinAlgError:
                continue
            F = np.zeros(m)
            F[W] = sol[: len(W)]
            a = sol[len(W) :]
            g = q + M @ F - A @ a
            if F.min() >= -1e-10 and g.min() >= -1e-10 and np.abs(F * g).max() < 1e-9:
                found.append((F, a))
    return found


@pytest.mark.parametrize("seed", range(6))
def test_matches_enumeration_of_active_sets(seed):
    rng = np.random.default_rng(seed)
    M, q, A, f = _random_problem(rng, 8)
    ref = _enumerate(M, q, A, f)
    assert len(ref) >= 1
    sol = solve_contact_qp(M, q, A, f)
    # the forces are unique (strictly convex QP); the multipliers are when A_W has full rank
    assert np.abs(sol.F - ref[0][0]).max() < 1e-10
    assert sol.F.min() >= 0.0
    assert sol.gap.min() > -1e-12
    assert sol.complementarity < 1e-12
    assert sol.equilibrium < 1e-12


def test_large_random_problems_meet_every_condition():
    rng = np.random.default_rng(11)
    for _ in range(20):
        M, q, A, f = _random_problem(rng, 120)
        s = solve_contact_qp(M, q, A, f)
        assert s.F.min() >= 0.0 and s.gap.min() > -1e-11
        assert s.complementarity < 1e-12 and s.equilibrium < 1e-12


def test_loads_no_contact_can_carry_are_an_error():
    # a torque (third equality) on contacts whose moment arms are all zero
    M = np.eye(4)
    q = np.ones(4)
    A = np.zeros((4, 3))
    A[:, 0] = [1, -1, 1, -1]
    with pytest.raises(ContactSolveError, match="cannot balance"):
        solve_contact_qp(M, q, A, np.array([0.0, 0.0, 5.0]))


def test_non_convergence_is_an_error():
    rng = np.random.default_rng(2)
    M, q, A, f = _random_problem(rng, 60)
    with pytest.raises(ContactSolveError, match="no convergence"):
        solve_contact_qp(M, q, A, f, max_iter=1, active=np.zeros(60, bool))
