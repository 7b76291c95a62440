"""Ring influence and nominal rim states at a model's fixed angles (teeth, balls), computed once per drive (docs/models.md 4.1)."""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from .ring import Ring

__all__ = ["RingTables", "ring_tables", "Compliance"]


@dataclass(frozen=True)
class RingTables:
    """Everything of the ring that one load state evaluates again and again, at the only angles that occur.

    Contact loads act at the tooth angles (``2 pi k / z_g`` from the major
    axis, the generator at angle 0) and at the ball angles, and the rim is
    observed at the tooth angles: the influence of every such load on every
    such point is one matrix, so a pass of the solver does a product where it
    evaluated the closed-form kernels of :class:`Ring` (the same numbers).

    Attributes
    ----------
    angles : (n,) float
        ``z_g`` tooth angles (wrapped to (-pi, pi]) then the ball angles, rad.
    z_g : int
    influence : (3 n, 3 n) float
        ``influence[3 i + o, 3 j + t] = Ring.block(angles[i] - angles[j])[o, t]``:
        output ``o`` (w, v, theta) at angle ``i`` per unit load of type ``t``
        (radial, tangential, couple) at angle ``j``.
    nominal : (S, 3, z_g) float
        ``w, v, theta`` of each section's nominal law at the tooth angles.
    centre_ball : (3, Z) float
        ``w, v, theta`` of the centre law at the ball angles (the cam's shape and normals there,
        docs/models.md 4.1).
    """

    angles: np.ndarray
    z_g: int
    influence: np.ndarray
    nominal: np.ndarray
    centre_ball: np.ndarray

    def tooth_field(self, loads: np.ndarray) -> np.ndarray:
        """Elastic ``w, v, theta`` at the tooth angles ``(3, z_g)`` from dense loads ``(n, 3)`` (one per angle)."""
        return (self.influence[: 3 * self.z_g] @ loads.ravel()).reshape(self.z_g, 3).T


def tooth_angles(z_g: int) -> np.ndarray:
    """Angles of the ``z_g`` teeth from the major axis, wrapped to (-pi, pi], rad (as the solver numbers them)."""
    phi = 2.0 * pi * np.arange(z_g) / z_g
    return np.where(phi > pi, phi - 2.0 * pi, phi)


def ring_tables(ring: Ring, z_g: int, ball_psi: np.ndarray, section_laws, centre_law) -> RingTables:
    """Build the :class:`RingTables` of a model (a few ms: ``(z_g + Z)^2`` kernel evaluations)."""
    phi_t = tooth_angles(z_g)
    ang = np.concatenate([phi_t, np.asarray(ball_psi, dtype=float)])
    n = len(ang)
    blk = ring.block(ang[:, None] - ang[None, :])  # (n, n, 3, 3): [obs, src, output, load type]
    influence = np.ascontiguousarray(blk.transpose(0, 2, 1, 3).reshape(3 * n, 3 * n))
    nominal = np.empty((len(section_laws), 3, z_g))
    for s, law in enumerate(section_laws):
        st = law.state(phi_t)
        nominal[s] = (st.w, st.v, st.theta)
    cb = centre_law.state(np.asarray(ball_psi, dtype=float))
    for a in (ang, influence, nominal):
        a.setflags(write=False)
    return RingTables(ang, int(z_g), influence, nominal, np.stack([cb.w, cb.v, cb.theta]))


class Compliance:
    """The contact compliance by columns: the ring part ``D_jl = f_j f_l b_j' C(phi_j - phi_l) b_l``, the contacts'
    own ``diag(s)``, and low-rank parts ``L R'`` (the cup's fields: docs/models.md 4.2).

    The contact solver needs only the columns of the contacts it loads (a
    few dozen of some hundreds in the band), so they are built on demand from
    the influence table and kept.

    Parameters
    ----------
    tables : RingTables
    idx : (m,) int
        Angle index of each contact in ``tables.angles``.
    fb : (m, 3) float
        ``f_j b_j``: how a unit contact force loads the ring (radial,
        tangential, couple) and how the ring's ``w, v, theta`` there close the gap.
    s : (m,) float
        The contacts' own compliances (Hertz, tooth bending), mm/N.
    """

    def __init__(self, tables: RingTables, idx: np.ndarray, fb: np.ndarray, s: np.ndarray):
        self._K = tables.influence
        m = len(idx)
        self._rows = (3 * idx[:, None] + np.arange(3)).ravel()  # (3 m,)
        self._fb = fb
        self._s = s
        self._D = np.empty((m, m))
        self._have = np.zeros(m, dtype=bool)
        self._extra = []  # (L, R): the low-rank parts L R', (m, k) each
        self.shape = (m, m)
        # D_jj = fb_j' C(0) fb_j: the 3x3 block at zero angle is the same for every angle
        c0 = self._K[:3, :3]
        self.diag = np.einsum("ja,ab,jb->j", fb, c0, fb) + s

    def cols(self, W: np.ndarray) -> np.ndarray:
        """``M[:, W]``, ``(m, len(W))``."""
        W = np.asarray(W, dtype=int)
        new = W[~self._have[W]]
        if new.size:
            m = self.shape[0]
            # the influence matrix is symmetric (Maxwell-Betti), so a load's column is its row: contiguous
            src = self._K[self._rows.reshape(m, 3)[new]]  # (k, 3, 3 n)
            Z = np.einsum("kar,ka->kr", src, self._fb[new])  # (k, 3 n)
            D = np.einsum("kja,ja->jk", Z[:, self._rows].reshape(len(new), m, 3), self._fb)
            D[new, np.arange(len(new))] += self._s[new]
            for L, R in self._extra:
                D += L @ R[new].T
            self._D[:, new] = D
            self._have[new] = True
        return self._D[:, W]

    def _with_extra(self, L: np.ndarray, R: np.ndarray) -> Compliance:
        new = object.__new__(Compliance)
        new.__dict__.update(self.__dict__)
        new._extra = self._extra + [(L, R)]
        new._D = self._D.copy()
        j = np.nonzero(self._have)[0]
        if j.size:
            new._D[:, j] += L @ R[j].T
        new._have = self._have.copy()
        new.diag = self.diag + (L * R).sum(axis=1)
        return new

    def with_field(self, U: np.ndarray, W: np.ndarray) -> Compliance:
        """The same compliance plus ``U W U'``: an elastic field (the cup's bending and twist between the contact
        planes, ``W`` symmetric positive semidefinite) that every contact feels through its rows ``U``."""
        U = np.asarray(U, dtype=float)
        return self._with_extra(U @ np.asarray(W, dtype=float), U)

    def with_contact(self, s: np.ndarray) -> Compliance:
        """The same ring part with contact compliances ``s`` ``(m,)`` on the diagonal (the columns built so far kept)."""
        new = object.__new__(Compliance)
        new.__dict__.update(self.__dict__)
        s = np.asarray(s, dtype=float)
        new._s = s
        new._D = self._D.copy()
        j = np.nonzero(self._have)[0]
        new._D[j, j] += s[j] - self._s[j]
        new._have = self._have.copy()
        new.diag = self.diag - self._s + s
        return new

    def dense(self) -> np.ndarray:
        """The whole matrix (tests, small problems)."""
        return self.cols(np.arange(self.shape[0]))
