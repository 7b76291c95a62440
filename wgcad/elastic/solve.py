"""Contact problem with equilibrium equalities: an exact active-set solver of the mixed LCP / convex QP (docs/models.md 4, 4.1)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg.lapack import dgelsd, dgelsd_lwork, dpotrf, dpotrs

from wgcad.errors import ModelError

__all__ = ["ContactSolveError", "QPSolution", "solve_contact_qp", "solve_supported"]


class ContactSolveError(ModelError):
    """The contact problem has no solution or the solver did not converge (never returned silently; exit code 4)."""


@dataclass(frozen=True, slots=True)
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

    def with_field(self, U, W):
        U = np.asarray(U, dtype=float)
        return _Dense(self.M + U @ np.asarray(W, dtype=float) @ U.T)


def _gap(M, q, A, F, a, W, MW=None):
    """``q + M F - A a`` for ``F`` supported on ``W`` (``MW``: ``M[:, W]`` when already at hand)."""
    return q + (M.cols(W) if MW is None else MW) @ F[W] - A @ a


def _kkt(M, q, A, f, W, MW=None, K=None):
    """Solve the equality-constrained system on the active set ``W``; least-norm multipliers when rank-deficient.

    ``gap_W = q_W + M_WW F_W - A_W a = 0`` and ``A' F + K a = f`` (``K`` the freedoms' support stiffnesses, 0 for
    free ones): ``(A_W' M_WW^-1 A_W + K) a = f + A_W' M_WW^-1 q_W``, then ``F_W = M_WW^-1 (A_W a - q_W)``.
    """
    m, r = A.shape
    F = np.zeros(m)
    k = np.zeros(r) if K is None else K
    if W.size == 0:
        a = np.zeros(r)
        sp = k > 0
        a[sp] = f[sp] / k[sp]
        return F, a
    Mw = (M.cols(W) if MW is None else MW)[W]
    Aw = A[W]
    # inputs are finite by construction (geometry and compliances checked where they are made); LAPACK called
    # directly (what cho_factor and cho_solve call): the systems are a few dozen unknowns, solved at every pivot,
    # where the wrappers' checks cost more than the factorisation
    c, info = dpotrf(Mw, lower=0, clean=0)
    if info != 0:
        raise np.linalg.LinAlgError(f"the active contacts' compliance is not positive definite (potrf {info})")
    y, _ = dpotrs(c, np.column_stack([q[W], Aw]), lower=0)
    y_q, y_A = y[:, 0], y[:, 1:]
    if r == 0:  # no body freedom (every one held): the contacts alone
        F[W] = -y_q
        return F, np.zeros(0)
    S = Aw.T @ y_A + np.diag(k)
    rhs = f + Aw.T @ y_q
    # S singular when the active contacts cannot hold a free body's motion; scaled to a unit diagonal first, so
    # that a stiff support (k up to 1e15) does not hide the free freedoms from the rank decision
    d = np.sqrt(np.abs(np.diag(S)))
    d = np.where(d > 0, d, 1.0)
    a = _least_norm(S / d[:, None] / d[None, :], rhs / d) / d
    F[W] = y_A @ a - y_q
    return F, a


_GELSD_WORK: dict = {}


def _least_norm(S: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """The least-norm least-squares solution of ``S x = rhs`` (singular values below 1e-12 of the largest dropped):
    LAPACK's gelsd, as ``numpy.linalg.lstsq(S, rhs, rcond=1e-12)`` computes it, without its per-call set-up."""
    n = S.shape[0]
    work = _GELSD_WORK.get(n)
    if work is None:
        lwork, iwork, _ = dgelsd_lwork(n, n, 1, 1e-12)
        work = _GELSD_WORK[n] = (int(lwork), int(iwork))
    x, _, _, info = dgelsd(S, rhs[:, None], work[0], work[1], 1e-12)
    if info != 0:
        raise np.linalg.LinAlgError(f"the freedoms' system did not solve (gelsd {info})")
    return x[:n, 0]


def solve_contact_qp(
    M, q, A, f, active=None, tol_gap: float = 1e-12, max_iter: int | None = None, stiffness=None
) -> QPSolution:
    """Exact solution of the mixed linear complementarity problem

    ``gap = q + M F - A a >= 0,  F >= 0,  F . gap = 0,  A' F + K a = f``

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
    stiffness : (r,) float, optional
        ``K``: each freedom's support stiffness (0, the default: a free body, its equation an equality).
    tol_gap : float
        Feasibility tolerance on gaps (mm) and, scaled by ``max |M|``, on forces.
    max_iter : int, optional
        Pivots at most (default ``500 + 4 m``). Murty's single pivots terminate but may walk through the
        contacts one at a time: a near-zero torque on D1 with sprung supports (the cam's preload pressing teeth
        that carry no torque) needs 699 pivots for 352 contacts, more than a fixed 500 allowed.

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
    K = None if stiffness is None else np.asarray(stiffness, dtype=float)
    act = (q < 0.0) if active is None else np.asarray(active, dtype=bool).copy()
    tol_F = tol_gap / max(float(np.abs(M.diag).max()) if m else 1.0, 1e-300)
    best, p_left = m + 1, 3
    max_iter = 500 + 4 * m if max_iter is None else int(max_iter)
    for it in range(max_iter):
        W = np.nonzero(act)[0]
        MW = M.cols(W)  # once per pivot: the system and the gaps both need these columns
        F, a = _kkt(M, q, A, f, W, MW, K)
        gap = _gap(M, q, A, F, a, W, MW)
        j = _closing_contact(A, f, F, a, K, act, gap)
        if j is not None:
            # the active contacts cannot hold a free body (its position along the free direction, and so every gap,
            # is then arbitrary): it moves until the first contact ahead closes
            act[j] = True
            continue
        bad_F = act & (F < -tol_F)
        bad_g = ~act & (gap < -tol_gap)
        n_bad = int(bad_F.sum() + bad_g.sum())
        if n_bad == 0:
            F = np.where(act, np.maximum(F, 0.0), 0.0)
            gap = _gap(M, q, A, F, a, W, MW)
            return _finish(M, q, A, f, F, a, gap, it, tol_gap, K)
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
    raise ContactSolveError(f"contact solver: no convergence in {max_iter} pivots ({best} contacts still infeasible)")


def _closing_contact(A, f, F, a, K, act, gap) -> int | None:
    """The contact a free body closes first when the active ones cannot hold it, or None when they do.

    With the active contacts unable to balance a free freedom's load (none of them touches it, or too few: the
    freedoms' system is singular and its least-norm answer leaves the load unbalanced), the body moves along the
    unbalanced load ``u = f - A'F - K a``, kept off the active contacts' normals (``A_W d = 0``), until an open
    contact closes: the smallest ``gap_j / (A_j . d)`` of those it approaches (negative too: the body's place along
    ``d`` is the least-norm one, arbitrary, so the first contact to close is judged along the whole line). None
    also where no contact lies ahead (then :func:`_finish` refuses the load).
    """
    if A.shape[1] == 0:
        return None
    spring = 0.0 if K is None else K * a
    u = f - A.T @ F - spring
    scale = max(float(np.abs(A * F[:, None]).max()) if F.size else 0.0, float(np.abs(f).max()), 1e-300)
    if float(np.abs(u).max()) <= 1e-9 * scale:
        return None
    Aw = A[act]
    d = u - Aw.T @ np.linalg.lstsq(Aw @ Aw.T, Aw @ u, rcond=1e-12)[0] if Aw.size else u
    rate = A @ d
    ahead = ~act & (rate > 1e-12 * float(np.abs(rate).max(initial=0.0)))
    if not ahead.any():
        return None
    idx = np.nonzero(ahead)[0]
    return int(idx[np.argmin(gap[idx] / rate[idx])])


def _finish(M, q, A, f, F, a, gap, it, tol_gap, K=None) -> QPSolution:
    if A.shape[1] == 0:
        eq = 0.0
    else:
        scale_f = float(np.abs(A * F[:, None]).max()) if F.size else 0.0
        spring = 0.0 if K is None else K * a
        eq = float(np.abs(A.T @ F + spring - f).max()) / max(scale_f, float(np.abs(f).max()), 1e-300)
    if eq > 1e-9:
        raise ContactSolveError(
            f"contact solver: the active contacts cannot balance the loads (equilibrium residual {eq:.2e}); "
            "no set of contacts can carry this torque"
        )
    qs = max(float(np.abs(q).max()) if q.size else 0.0, tol_gap)
    Fs = max(float(F.max()) if F.size else 0.0, 1e-300)
    comp = float(np.abs(F * gap).max()) / (Fs * qs) if F.size else 0.0
    return QPSolution(F, a, gap, it + 1, comp, eq)


def solve_supported(M, q, A, f, stiffness, active=None, field=None) -> QPSolution:
    """:func:`solve_contact_qp` with the rigid-body freedoms ``A`` ``(m, r)`` each free, sprung or held.

    ``stiffness`` ``(r,)`` per freedom (N/mm or N mm/rad): 0, a free body
    (an equality ``A_j' F = f_j``, its displacement a multiplier); ``inf``,
    held (the freedom dropped); else an elastic support: ``A_j' F + k_j a_j = f_j``
    (the body moves by its net load over the stiffness, docs/models.md 4.1; solved in that form, not as the
    compliance ``A_j A_j' / k_j``, so that neither limit loses precision). ``field``: ``(U, W)``, an elastic field
    whose compliance ``U W U'`` joins the contacts' (``M`` must offer ``with_field``, docs/models.md 4.2).
    The returned ``a`` has all ``r`` freedoms (0 for the held ones).
    """
    M = M if hasattr(M, "cols") else _Dense(M)
    k = np.asarray(stiffness, dtype=float)
    keep = np.isfinite(k)
    q = np.asarray(q, dtype=float)
    A = np.asarray(A, dtype=float)
    f = np.asarray(f, dtype=float)
    if field is not None:
        M = M.with_field(*field)
    sol = solve_contact_qp(M, q, A[:, keep], f[keep], active=active, stiffness=k[keep])
    a = np.zeros(len(k))
    a[keep] = sol.a
    return replace(sol, a=a)
