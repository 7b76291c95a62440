"""Exact curve pieces of a tooth outline: involutes, arcs, lines, epi/hypocycloids with their derivatives (docs/models.md 2.1, 2.2).

A :class:`Piece` is one analytic curve over a parameter range ``t0 -> t1``
(either order: the piece runs from ``point(t0)`` to ``point(t1)``). The
sampled polygons of :mod:`wgcad.profiles.gear` are vertices of these pieces;
the pieces are what exports can write as arcs and what the clearance engine
refines on.

Kinds and parameters (``params``)
---------------------------------
``"arc"``          ``(cx, cy, radius)``: ``C + R (cos t, sin t)``, ``t`` the
                   polar angle about the centre (world frame, no ``rot``/``flip``).
``"line"``         ``(x0, y0, dx, dy)``: ``P0 + t D``, ``t`` in ``[0, 1]``.
``"involute"``     ``(psi_base, r_base)``: ``r_b sqrt(1+t^2) (cos a, sin a)``,
                   ``a = psi_base - (t - atan t)``, ``t`` the roll parameter.
``"epicycloid"``   ``(r, rho)``: :func:`wgcad.profiles.cycloid.epicycloid` of roll angle
                   ``phi``, with ``t = 1 - cos(phi/2)`` (constant speed: no stationary
                   parameter at the pitch-point cusp, see :func:`roll_to_u`).
``"hypocycloid"``  ``(r, rho)``: :func:`wgcad.profiles.cycloid.hypocycloid`, same parameter.
``"cubic"``        ``(x0, y0, x1, y1, x2, y2, x3, y3)``: the cubic Bezier curve of these
                   control points, ``t`` in ``[0, 1]``.
``"spline"``       ``n`` such Bezier segments end to end (``8 n`` numbers), ``t`` in ``[0, n]``,
                   segment ``floor(t)``: a tangent-continuous Hermite spline through exact points with their
                   tangents (the conjugate flank, docs/models.md 13), one piece so that exports
                   fit it with few arcs.

Non-arc, non-line kinds are then mirrored (``flip = -1``: ``y -> -y``) and
turned by ``rot`` about the origin: ``point = R(rot) diag(1, flip) base(t)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.polynomial.legendre import leggauss

__all__ = [
    "Piece",
    "arc",
    "line",
    "involute",
    "cycloid",
    "cubic",
    "spline",
    "roll_to_u",
    "mirror_path",
    "merge_arcs",
    "path_points",
]


def _rot(v: np.ndarray, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


@lru_cache(maxsize=8)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1], ``(n,)`` each, read-only: numpy's ``leggauss``, kept per ``n``
    (every arc length asks for the same few rules)."""
    x, w = leggauss(n)
    x.setflags(write=False)
    w.setflags(write=False)
    return x, w


@dataclass(frozen=True, slots=True)
class Piece:
    """One analytic piece of an outline (module docstring). Lengths mm, angles rad.

    Attributes
    ----------
    kind : str
        ``"arc"``, ``"line"``, ``"involute"``, ``"epicycloid"`` or ``"hypocycloid"``.
    t0, t1 : float
        Parameter at the start and at the end of the piece (``t1 < t0`` allowed).
    params : tuple of float
        Kind-specific parameters (module docstring).
    rot : float
        Turn applied after the canonical curve (not used by arcs and lines).
    flip : float
        ``+1`` or ``-1`` (mirror ``y -> -y`` before ``rot``; not used by arcs and lines).
    """

    kind: str
    t0: float
    t1: float
    params: tuple
    rot: float = 0.0
    flip: float = 1.0

    # -- geometry -----------------------------------------------------------------
    @property
    def center(self) -> np.ndarray:
        """Centre ``(2,)`` of an arc, mm."""
        if self.kind != "arc":
            raise AttributeError(f"a {self.kind} piece has no centre")
        return np.array(self.params[:2], dtype=float)

    @property
    def radius(self) -> float:
        """Radius of an arc, mm."""
        if self.kind != "arc":
            raise AttributeError(f"a {self.kind} piece has no radius")
        return float(self.params[2])

    @property
    def start(self) -> np.ndarray:
        """First point ``(2,)``."""
        return self.point(np.array([self.t0]))[0]

    @property
    def end(self) -> np.ndarray:
        """Last point ``(2,)``."""
        return self.point(np.array([self.t1]))[0]

    def point(self, t) -> np.ndarray:
        """Points ``(n, 2)`` at parameters ``t (n,)``."""
        return self._eval(np.atleast_1d(np.asarray(t, dtype=float)), 0)

    def deriv(self, t) -> np.ndarray:
        """First derivatives ``dP/dt``, ``(n, 2)``."""
        return self._eval(np.atleast_1d(np.asarray(t, dtype=float)), 1)

    def deriv2(self, t) -> np.ndarray:
        """Second derivatives ``d2P/dt2``, ``(n, 2)``."""
        return self._eval(np.atleast_1d(np.asarray(t, dtype=float)), 2)

    def length(self, n: int = 64) -> float:
        """Arc length (Gauss-Legendre on ``n`` nodes, each spline segment its own; exact for arcs and lines), mm."""
        if self.kind == "arc":
            return abs(self.t1 - self.t0) * self.radius
        if self.kind == "line":
            return abs(self.t1 - self.t0) * float(np.hypot(self.params[2], self.params[3]))
        x, w = gauss_legendre(n)
        lo, hi = sorted((self.t0, self.t1))
        # a spline's speed jumps at its knots: the rule runs over each segment, where it is smooth (over the whole
        # range it was 0.3 % short on a five-point spline)
        cuts = np.arange(np.floor(lo) + 1.0, np.ceil(hi)) if self.kind == "spline" else np.zeros(0)
        ends = np.concatenate([[lo], cuts, [hi]])
        total = 0.0
        for a, b in zip(ends[:-1], ends[1:]):
            h = 0.5 * (b - a)
            d = self.deriv(a + h * (x + 1.0))
            total += h * float(np.dot(w, np.hypot(d[:, 0], d[:, 1])))
        return total

    # -- transforms ----------------------------------------------------------------
    def reversed(self) -> Piece:
        """The same curve run the other way."""
        return Piece(self.kind, self.t1, self.t0, self.params, self.rot, self.flip)

    def mirrored(self) -> Piece:
        """Mirror image about the x axis (``y -> -y``), same direction of travel along the image."""
        if self.kind == "arc":
            cx, cy, R = self.params
            return Piece("arc", -self.t0, -self.t1, (cx, -cy, R))
        if self.kind == "line":
            x0, y0, dx, dy = self.params
            return Piece("line", self.t0, self.t1, (x0, -y0, dx, -dy))
        # diag(1,-1) R(a) = R(-a) diag(1,-1)
        return Piece(self.kind, self.t0, self.t1, self.params, -self.rot, -self.flip)

    def rotated(self, angle: float) -> Piece:
        """Turned by ``angle`` (rad, counter-clockwise) about the origin."""
        if self.kind == "arc":
            cx, cy, R = self.params
            c = _rot(np.array([cx, cy]), angle)
            return Piece("arc", self.t0 + angle, self.t1 + angle, (float(c[0]), float(c[1]), R))
        if self.kind == "line":
            x0, y0, dx, dy = self.params
            p, d = _rot(np.array([x0, y0]), angle), _rot(np.array([dx, dy]), angle)
            return Piece("line", self.t0, self.t1, (float(p[0]), float(p[1]), float(d[0]), float(d[1])))
        return Piece(self.kind, self.t0, self.t1, self.params, self.rot + angle, self.flip)

    # -- evaluation ---------------------------------------------------------------
    def _eval(self, t: np.ndarray, order: int) -> np.ndarray:
        k = self.kind
        if k == "arc":
            cx, cy, R = self.params
            c, s = np.cos(t), np.sin(t)
            if order == 0:
                return np.stack([cx + R * c, cy + R * s], axis=-1)
            if order == 1:
                return np.stack([-R * s, R * c], axis=-1)
            return np.stack([-R * c, -R * s], axis=-1)
        if k == "line":
            x0, y0, dx, dy = self.params
            if order == 0:
                return np.stack([x0 + t * dx, y0 + t * dy], axis=-1)
            d = np.array([dx, dy]) if order == 1 else np.zeros(2)
            return np.broadcast_to(d, (len(t), 2)).copy()
        if k == "involute":
            out = _involute(self.params, t, order)
        elif k == "epicycloid":
            out = _cycloid(self.params, t, order, +1.0)
        elif k == "hypocycloid":
            out = _cycloid(self.params, t, order, -1.0)
        elif k == "cubic":
            out = _cubic(self.params, t, order)
        elif k == "spline":
            n = len(self.params) // 8
            seg = np.clip(np.floor(t), 0, n - 1).astype(int)
            P = np.asarray(self.params, dtype=float).reshape(n, 8)[seg]
            out = _bezier(P, t - seg, order)
        else:  # pragma: no cover - constructors only make the kinds above
            raise ValueError(f"unknown piece kind {k!r}")
        if self.flip < 0:
            out = out * np.array([1.0, -1.0])
        return _rot(out, self.rot) if self.rot else out


def _cubic(params, t, order):
    """The Bezier curve of control points ``params`` and its derivatives in ``t``."""
    return _bezier(np.broadcast_to(np.asarray(params, dtype=float), (len(t), 8)), t, order)


def _bezier(P, t, order):
    """Bezier segments ``P (K, 8)`` (four control points each) at ``t (K,)`` and their derivatives."""
    P0, P1, P2, P3 = P[:, 0:2], P[:, 2:4], P[:, 4:6], P[:, 6:8]
    t = t[:, None]
    u = 1.0 - t
    if order == 0:
        return u**3 * P0 + 3 * u * u * t * P1 + 3 * u * t * t * P2 + t**3 * P3
    if order == 1:
        return 3 * u * u * (P1 - P0) + 6 * u * t * (P2 - P1) + 3 * t * t * (P3 - P2)
    return 6 * u * (P2 - 2 * P1 + P0) + 6 * t * (P3 - 2 * P2 + P1)


def _involute(params, t, order):
    """Polar form ``rad(t) (cos a(t), sin a(t))`` and its derivatives (docs/models.md 2.1)."""
    psi, rb = params
    s2 = 1.0 + t * t
    s = np.sqrt(s2)
    a = psi - (t - np.arctan(t))
    u = np.stack([np.cos(a), np.sin(a)], axis=-1)
    n = np.stack([-np.sin(a), np.cos(a)], axis=-1)
    rad = rb * s
    if order == 0:
        return rad[:, None] * u
    rad1 = rb * t / s
    a1 = -t * t / s2
    if order == 1:
        return rad1[:, None] * u + (rad * a1)[:, None] * n
    rad2 = rb / (s2 * s)
    a2 = -2.0 * t / (s2 * s2)
    second = (rad2 - rad * a1 * a1)[:, None] * u + (2.0 * rad1 * a1 + rad * a2)[:, None] * n
    if order == 2:
        return second
    return rad[:, None] * u, rad1[:, None] * u + (rad * a1)[:, None] * n, second  # order -1: all three


def _cycloid(params, u, order, sgn):
    """Epicycloid (``sgn = +1``) or hypocycloid (``-1``) at ``u = 1 - cos(phi/2)`` and its derivatives in ``u`` (docs/models.md 2.2).

    ``P = (r + s rho) e(th) - s rho e(th + s phi)``, ``th = rho phi / r``,
    ``phi`` the roll angle. In ``u`` the speed is constant,
    ``|dP/du| = 4 rho (1 + s rho / r)`` (``u`` is proportional to the arc
    length from the cusp on the pitch circle), so the parameter has no
    stationary point at the pitch point where the two flank pieces meet;
    the curvature there is infinite (a cusp of either cycloid), and
    ``d2P/du2`` grows like ``1/sqrt(u)`` toward it.
    """
    r, rho = params
    k = rho / r
    A = r + sgn * rho
    u = np.clip(u, 0.0, 2.0)
    phi = 4.0 * np.arcsin(np.sqrt(0.5 * u))
    if order in (0, -1):
        a1, a2 = k * phi, (k + sgn) * phi
        p0 = np.stack([A * np.cos(a1) - sgn * rho * np.cos(a2), A * np.sin(a1) - sgn * rho * np.sin(a2)], axis=-1)
        if order == 0:
            return p0
    m = 0.5 * (2.0 * k + sgn) * phi
    cm, sm = np.cos(m), np.sin(m)
    speed = 4.0 * A * k * sgn
    p1 = np.stack([speed * cm, speed * sm], axis=-1)
    if order == 1:
        return p1
    half = np.maximum(np.sin(0.5 * phi), 1e-12)
    mu = (2.0 * k + sgn) / half
    p2 = np.stack([-speed * mu * sm, speed * mu * cm], axis=-1)
    if order == 2:
        return p2
    return p0, p1, p2


def roll_to_u(phi):
    """Cycloid piece parameter ``u = 1 - cos(phi / 2)`` of roll angle ``phi`` (0 at the pitch circle, 1 at ``phi = pi``)."""
    return 2.0 * np.sin(0.25 * np.asarray(phi, dtype=float)) ** 2


# -- constructors ------------------------------------------------------------------
def arc(center, radius: float, a0: float, a1: float) -> Piece:
    """Arc of ``radius`` about ``center`` from polar angle ``a0`` to ``a1`` (about the centre)."""
    return Piece("arc", float(a0), float(a1), (float(center[0]), float(center[1]), float(radius)))


def line(p0, p1) -> Piece:
    """Segment from ``p0`` to ``p1``."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    d = p1 - p0
    return Piece("line", 0.0, 1.0, (float(p0[0]), float(p0[1]), float(d[0]), float(d[1])))


def cubic(p0, m0, p1, m1) -> Piece:
    """The cubic Hermite segment from ``p0`` to ``p1`` with end derivatives ``m0``, ``m1`` (per unit ``t``), as a
    Bezier piece."""
    p0, m0, p1, m1 = (np.asarray(a, dtype=float) for a in (p0, m0, p1, m1))
    c = np.concatenate([p0, p0 + m0 / 3.0, p1 - m1 / 3.0, p1])
    return Piece("cubic", 0.0, 1.0, tuple(float(x) for x in c))


def spline(points, tangents) -> Piece:
    """The cubic Hermite spline through ``points (n, 2)`` with unit ``tangents (n, 2)`` (each segment's end
    derivatives its chord times the tangents), one piece of ``n - 1`` Bezier segments, ``t`` in ``[0, n - 1]``:
    tangent-continuous, its derivative's length and second derivative jumping at the knots."""
    p = np.asarray(points, dtype=float)
    d = np.asarray(tangents, dtype=float)
    # each segment's end derivatives scaled by its own chord: with uneven knots (a flank's ends are found finely)
    # a knot's mean chord overshot the short segments by 0.1 um; the spline is then tangent-continuous (G1),
    # its derivative's length jumping at the knots
    L = np.hypot(*np.diff(p, axis=0).T)[:, None]
    c = np.concatenate([p[:-1], p[:-1] + d[:-1] * L / 3.0, p[1:] - d[1:] * L / 3.0, p[1:]], axis=1)
    return Piece("spline", 0.0, float(len(p) - 1), tuple(float(x) for x in c.ravel()))


def involute(psi_base: float, r_base: float, t0: float, t1: float) -> Piece:
    """The involute of :func:`wgcad.profiles.involute.involute_flank` from roll parameter ``t0`` to ``t1``."""
    return Piece("involute", float(t0), float(t1), (float(psi_base), float(r_base)))


def cycloid(kind: str, r: float, rho: float, phi0: float, phi1: float, rot: float = 0.0, flip: float = 1.0) -> Piece:
    """Epi/hypocycloid (``kind``) on pitch radius ``r``, rolling radius ``rho``, from roll angle ``phi0`` to ``phi1``.

    The piece's parameter is ``u = 1 - cos(phi/2)`` (:func:`roll_to_u`), not the roll angle.
    """
    return Piece(kind, float(roll_to_u(phi0)), float(roll_to_u(phi1)), (float(r), float(rho)), float(rot), float(flip))


# -- paths -------------------------------------------------------------------------
def mirror_path(pieces) -> list[Piece]:
    """The mirror image (``y -> -y``) of a path of pieces, run backwards: the path that leads into it."""
    return [p.mirrored().reversed() for p in reversed(list(pieces))]


def merge_arcs(pieces, tol: float = 1e-12) -> list[Piece]:
    """Join consecutive arcs of one circle that continue each other into one arc."""
    out: list[Piece] = []
    for p in pieces:
        if out and p.kind == "arc" and out[-1].kind == "arc":
            q = out[-1]
            same = all(abs(a - b) <= tol * max(1.0, abs(b)) for a, b in zip(p.params, q.params))
            if same and abs(p.t0 - q.t1) <= tol and (p.t1 - p.t0) * (q.t1 - q.t0) >= 0:
                out[-1] = Piece("arc", q.t0, p.t1, q.params)
                continue
        out.append(p)
    return out


def path_points(pieces, n: int = 16) -> np.ndarray:
    """``n`` evenly spaced parameter points per piece, concatenated ``(len(pieces) * n, 2)`` (for plots and tests)."""
    return np.concatenate([p.point(np.linspace(p.t0, p.t1, n)) for p in pieces])
