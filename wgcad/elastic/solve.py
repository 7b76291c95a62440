"""Contact problem with equilibrium equalities: an exact active-set solver of the mixed LCP / convex QP (docs/models.md 4, 4.1)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from wgcad.errors import ModelError

from ..records import record

__all__ = ["ContactSolveError", "QPSolution", "solve_contact_qp", "solve_supported"]


class ContactSolveError(ModelError):
    """The contact problem has no solution or the solver did not converge (never returned silently; exit code 4)."""


@record(frozen=True)
class QPSolution:
    """Solution of ``min 1/2 F'MF + q'F  s.t.  F >= 0,  A'F = f`` and its checks.

    Attributes
    ----------
    F : (m,) float
        Contact forces, N (>= 0).
    a : (r,) float
        Multipliers of the equalities: the rigid-body displacements.
    gap : (m,) float
        ``q + M F - A a`` (>= 0), mm.
    iterations : int
        Block pivots taken.
    complementarity : float
        ``max |F_j gap_j|`` divided by ``max F * max |q|`` (dimensionless).
    equilibrium : float
        ``|A'F - f|`` relative to the largest single contribution ``|A_j| F_j``.
    """

    F: np.ndarray
    a: np.ndarray
    gap: np.ndarray
    iterations: int
    complementarity: float
    equilibrium: float


class _Dense:
    """A dense matrix seen through the column interface the solver uses (``cols``, ``diag``)."""

    def __init__(self, M):
        self.M = np.asarray(M, dtype=float)
        self.diag = np.diag(self.M)
        self.shape = self.M.shape

    def cols(self, W):
        return self.M[:, W]


def _gap(M, q, A, F, a, W, MW=None):
    """``q + M F - A a`` for ``F`` supported on ``W`` (``MW``: ``M[:, W]`` when already at hand)."""
    return q + (M.cols(W) if MW is None else MW) @ F[W] - A @ a


def _kkt(M, q, A, f, W, MW=None):
    """Solve the equality-constrained system on the active set ``W``; least-norm multipliers when rank-deficient."""
    m, r = A.shape
    F = np.zeros(m)
    if W.size == 0:
        return F, np.zeros(r)
    Mw = (M.cols(W) if MW is None else MW)[W]
    Aw = A[W]
    # inputs are finite by construction (geometry and compliances checked where they are made)
    cf = cho_factor(Mw, check_finite=False)
    y = cho_solve(cf, np.column_stack([q[W], Aw]), check_finite=False)
    y_q, y_A = y[:, 0], y[:, 1:]
    if r == 0:  # no free body (every freedom held or sprung): the contacts alone
        F[W] = -y_q
        return F, np.zeros(0)
    S = Aw.T @ y_A
    rhs = f + Aw.T @ y_q
    # S = A_W' M_WW^-1 A_W: singular when the active contacts cannot hold a rigid-body motion
    a, *_ = np.linalg.lstsq(S, rhs, rcond=1e-12)
    F[W] = y_A @ a - y_q
    return F, a


def solve_contact_qp(M, q, A, f, active=None, tol_gap: float = 1e-12, max_iter: int = 500) -> QPSolution:
    """Exact solution of the mixed linear complementarity problem

    ``gap = q + M F - A a >= 0,  F >= 0,  F . gap = 0,  A' F = f``

    (the KKT conditions of the strictly convex QP above, docs/models.md 4), by
    block principal pivoting (Judice & Pires 1994) with Murty's single pivot
    as the anti-cycling fallback. ``M`` must be symmetric positive definite
    (ring compliance plus positive contact compliances).

    Parameters
    ----------
    M : (m, m) float, or an object with ``cols(W)`` (the columns ``M[:, W]``), ``diag`` and ``shape``
        (a compliance built column by column, :class:`~wgcad.elastic.tables.Compliance`).
    q : (m,) float
    A : (m, r) float
    f : (r,) float
    active : (m,) bool, optional
        Warm start: contacts guessed to carry load.
    tol_gap : float
        Feasibility tolerance on gaps (mm) and, scaled by ``max |M|``, on forces.

    Raises
    ------
    ContactSolveError
        No convergence in ``max_iter`` pivots, or the equalities cannot be met
        by any set of contacts (e.g. a torque and no tooth that can carry it).
    """
    M = M if hasattr(M, "cols") else _Dense(M)
    q = np.asarray(q, dtype=float)
    A = np.asarray(A, dtype=float)
    f = np.asarray(f, dtype=float)
    m = len(q)
    act = (q < 0.0) if active is None else np.asarray(active, dtype=bool).copy()
    tol_F = tol_gap / max(float(np.abs(M.diag).max()) if m else 1.0, 1e-300)
    best, p_left = m + 1, 3
    for it in range(max_iter):
        W = np.nonzero(act)[0]
        MW = M.cols(W)  # once per pivot: the system and the gaps both need these columns
        F, a = _kkt(M, q, A, f, W, MW)
        gap = _gap(M, q, A, F, a, W, MW)
        bad_F = act & (F < -tol_F)
        bad_g = ~act & (gap < -tol_gap)
        n_bad = int(bad_F.sum() + bad_g.sum())
        if n_bad == 0:
            F = np.where(act, np.maximum(F, 0.0), 0.0)
            gap = _gap(M, q, A, F, a, W, MW)
            return _finish(M, q, A, f, F, a, gap, it, tol_gap)
        if n_bad < best:
            best, p_left = n_bad, 3
            flip = bad_F | bad_g
        elif p_left > 0:
            p_left -= 1
            flip = bad_F | bad_g
        else:
            j = int(np.max(np.nonzero(bad_F | bad_g)[0]))
            flip = np.zeros(m, dtype=bool)
            flip[j] = True
        act ^= flip
    raise ContactSolveError(
        f"contact solver: no convergence in {max_iter} block pivots ({best} contacts still infeasible)"
    )


def _finish(M, q, A, f, F, a, gap, it, tol_gap) -> QPSolution:
    if A.shape[1] == 0:
        eq = 0.0
    else:
        scale_f = float(np.abs(A * F[:, None]).max()) if F.size else 0.0
        eq = float(np.abs(A.T @ F - f).max()) / max(scale_f, float(np.abs(f).max()), 1e-300)
    if eq > 1e-9:
        raise ContactSolveError(
            f"contact solver: the active contacts cannot balance the loads (equilibrium residual {eq:.2e}); "
            "no set of contacts can carry this torque"
        )
    qs = max(float(np.abs(q).max()) if q.size else 0.0, tol_gap)
    Fs = max(float(F.max()) if F.size else 0.0, 1e-300)
    comp = float(np.abs(F * gap).max()) / (Fs * qs) if F.size else 0.0
    return QPSolution(F, a, gap, it + 1, comp, eq)


def solve_supported(M, q, A, f, stiffness, active=None) -> QPSolution:
    """:func:`solve_contact_qp` with the rigid-body freedoms ``A`` ``(m, r)`` each free, sprung or held.

    ``stiffness`` ``(r,)`` per freedom (N/mm or N mm/rad): 0, a free body
    (an equality ``A_j' F = f_j``, its displacement a multiplier); ``inf``,
    held (the freedom dropped); else an elastic support, whose compliance
    ``A_j A_j' / k_j`` joins the contact compliance (``M`` must offer
    ``with_support``) and whose displacement is
    ``a_j = -(A_j' F - f_j) / k_j`` (docs/models.md 4.1). The returned ``a``
    has all ``r`` freedoms.
    """
    k = np.asarray(stiffness, dtype=float)
    eq = k == 0.0
    sp = np.isfinite(k) & (k > 0.0)
    q = np.asarray(q, dtype=float)
    A = np.asarray(A, dtype=float)
    f = np.asarray(f, dtype=float)
    if sp.any():
        c = 1.0 / k[sp]
        As = A[:, sp]
        M = M.with_support(As, c)
        q = q - As @ (c * f[sp])
    sol = solve_contact_qp(M, q, A[:, eq], f[eq], active=active)
    a = np.zeros(len(k))
    a[eq] = sol.a
    if sp.any():
        a[sp] = -c * (As.T @ sol.F - f[sp])
    return replace(sol, a=a)
