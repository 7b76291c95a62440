"""The flexspline mounted on the cam: ball contacts along the cam's normals, the cam sized to the design's W0, the no-load state (docs/models.md 4.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .solve import ContactSolveError, solve_supported
from .tables import Compliance

__all__ = [
    "BallRows",
    "ball_rows",
    "ball_problem",
    "field_displacement",
    "MountedState",
    "mounted",
    "cam_excess",
    "generator_torque",
]

#: The cam's size is found when the mounted rim's W0 is within this of the design's, mm (1 nm).
_W0_TOL = 1e-6
#: Hertz re-linearisations of the mounting solve (the approach is ~ P^(2/3): a few passes settle it to < 1 nm).
_HERTZ_PASSES = 12
#: Force floor of the balls' Hertz secants, N (as the load states, state.FORCE_FLOOR).
_FLOOR = 1e-2


@dataclass(frozen=True, slots=True)
class BallRows:
    """The balls' rows of the linearised contact problem (docs/models.md 4.1).

    A ball at angle ``psi`` presses the rim along the cam's normal there, which
    is the normal of the deformed rim turned by the law's ``theta``: per unit
    force it loads the ring radially by 1 and tangentially by ``theta``, and a
    rim motion ``(w, v)`` opens its gap by ``w + theta v`` (the same vector both
    ways, so the compliance stays symmetric). ``gap = q + (D F + approach) - b . U - A . a``
    with ``U`` the ring's elastic ``w, v, theta`` at the ball and ``a`` the rim's
    rigid motion ``(dx, dy, rot)``.

    Attributes
    ----------
    b : (Z, 3) float
        ``(-1, -theta, 0)``.
    A : (Z, 5) float
        ``-d gap / d a`` for the rim's ``dx, dy, rot`` and the cam's ``dx, dy``:
        ``(-cos + theta sin, -sin - theta cos, v - theta (r_m + w), n_x, n_y)`` (the law's ``w, v, theta``
        at the ball; the third is ``-w'`` to first order: the cam's slope is the ball's lever; a cam moving
        along ``n`` closes the gap).
    q : (Z,) float
        Gap at the ball with the rim round and unloaded, the cam centred, mm.
    normal : (Z, 2) float
        The cam's outward normal at each ball, generator frame.
    """

    b: np.ndarray
    A: np.ndarray
    q: np.ndarray
    normal: np.ndarray


def ball_rows(model, excess: float, e=(0.0, 0.0)) -> BallRows:
    """The balls' rows for a cam ``excess`` (``k`` of :func:`cam_excess`) and a cam offset ``e`` (mm, generator frame).

    The cam is the rim's nominal law (the design's W0) scaled by ``1 + k``
    and set inside the rim by the bearing's radial clearance ``c``: with the
    rim on the law its gap at a ball is ``c - k w``, and the round rim's gap
    ``q = c - k w - (w + theta v)`` (docs/models.md 4.1). The offset moves the
    cam along ``e``, closing each gap by ``n . e``.
    """
    br = model.bearing
    psi = br.psi
    w, v, th = model.tables.centre_ball
    c, s = np.cos(psi), np.sin(psi)
    r = model.drive.r_m
    b = np.stack([-np.ones_like(psi), -th, np.zeros_like(psi)], axis=-1)
    normal = np.stack([c - th * s, s + th * c], axis=-1)
    A = np.stack([-c + th * s, -s - th * c, v - th * (r + w), normal[:, 0], normal[:, 1]], axis=-1)
    e = np.asarray(e, dtype=float)
    q = br.clearance - excess * w - (w + th * v) - normal @ e
    return BallRows(b, A, q, normal)


@dataclass(frozen=True, slots=True)
class MountedState:
    """The rim pressed onto the cam by the balls alone (no teeth, no torque): the drive at no load before the mesh.

    Attributes
    ----------
    loads : (n, 3) float
        Generalized loads on the ring at the table's angles (the balls' forces).
    motion : Motion
        Where the members stand (the rim against its supports, the cam against its own).
    force : (Z,) float
        Ball forces, N.
    w0 : float
        Radial displacement of the rim at the major axis (tooth 0, generator centre section), mm.
    """

    loads: np.ndarray
    motion: object
    force: np.ndarray
    w0: float

    @property
    def rigid(self) -> np.ndarray:
        """The rim against the rigid gear at the generator's centre plane, ``dx, dy, rot``."""
        return self.motion.centre

    @property
    def cam(self) -> np.ndarray:
        return self.motion.cam


def ball_problem(model, rows: BallRows):
    """The balls' freedom columns ``(Z, r)`` and the cup's field ``(U, W)`` (or None) at the ball plane."""
    sup = model.supports
    Z = len(rows.q)
    plane = np.full(Z, sup.ball_plane)
    A3 = rows.A[:, :3]
    return sup.columns(A3, rows.A[:, 3:5], plane, np.zeros(Z, dtype=bool)), sup.field(A3, plane)


def field_displacement(field, F: np.ndarray):
    """The cup's field displacements ``-W U' F`` under contact forces ``F`` (None without a field)."""
    if field is None:
        return None
    U, W = field
    return -(W @ (U.T @ F))


def _solve_mount(model, rows: BallRows) -> MountedState:
    """Balls only: ``gap = q + (D + s) F - A a >= 0``, ``A'F = 0``, the Hertz approach re-linearised to convergence."""
    tab = model.tables
    br = model.bearing
    Z = len(br.psi)
    idx = tab.z_g + np.arange(Z)
    F = np.zeros(Z)
    active = rows.q < 0.0
    A, fld = ball_problem(model, rows)
    # the rim's rotation held: without teeth nothing but the balls' slight tilt sets it (a ring turns freely
    # on its cam); the mesh sets it once the teeth are in (docs/models.md 4.1)
    k = model.support_stiffness.copy()
    k[0] = np.inf
    for _ in range(_HERTZ_PASSES):
        off, slope = br.tangent(F, _FLOOR)
        M = Compliance(tab, idx, rows.b, slope)
        sol = solve_supported(M, rows.q + off, A, np.zeros(A.shape[1]), k, active=active, field=fld)
        done = np.abs(sol.F - F).max() <= 1e-9 * max(float(sol.F.max()), 1.0)
        F, active = sol.F, sol.F > 0
        if done:
            break
    else:
        raise ContactSolveError(
            "the rim does not settle on the cam: ball forces still changing after "
            f"{_HERTZ_PASSES} Hertz re-linearisations"
        )
    loads = np.zeros((len(tab.angles), 3))
    np.add.at(loads, idx, -F[:, None] * rows.b)
    el = tab.tooth_field(loads)
    motion = model.supports.plane_motion(sol.a, field_displacement(fld, F))
    w0 = float(el[0, 0] + motion.centre[0])  # tooth 0 sits at angle 0: w = elastic + dx
    return MountedState(loads, motion, F, w0)


def cam_excess(model) -> float:
    """The cam's excess ``k`` over the rim's law that puts the mounted rim's major axis at the design's W0.

    With ``k = 0`` the cam is the law itself, ``c`` inside the rim all round,
    and the rim, which cannot stretch, settles short of W0; the cam is ground
    larger until it does not. The mounted W0 rises with ``k`` (piecewise
    linearly as balls join the contact): secant steps, bisection as the
    safeguard. Cached on the model.
    """
    key = "cam_excess"
    if key in model.cache:
        return model.cache[key]
    w0 = model.drive.law.w0
    target = w0

    def g(k):
        return _solve_mount(model, ball_rows(model, k)).w0 - target

    c = model.bearing.clearance
    step = max(2.0 * c / w0, 1e-3)
    a, ga = 0.0, g(0.0)
    if ga < 0.0:  # the usual case: the clearance lets the rim settle short of W0; grind the cam larger
        b, gb = step, g(step)
        while gb < 0.0:
            a, ga, b = b, gb, 2.0 * b
            gb = g(b)
    else:  # no clearance to take up (the rim already reaches W0): the cam a hair smaller
        b, gb = a, ga
        a, ga = -step, g(-step)
        while ga >= 0.0:
            b, gb, a = a, ga, 2.0 * a
            ga = g(a)
    k = b
    for _ in range(60):
        k = b - gb * (b - a) / (gb - ga) if gb != ga else 0.5 * (a + b)
        if not (a < k < b):
            k = 0.5 * (a + b)
        gk = g(k)
        if abs(gk) <= _W0_TOL:
            break
        if gk < 0.0:
            a, ga = k, gk
        else:
            b, gb = k, gk
    model.cache[key] = float(k)
    return float(k)


def mounted(model, e=(0.0, 0.0)) -> MountedState:
    """The no-load state on the cam (offset ``e``, mm), cached on the model."""
    e = np.asarray(e, dtype=float)
    key = ("mounted", float(e[0]), float(e[1]))
    if key not in model.cache:
        model.cache[key] = _solve_mount(model, ball_rows(model, cam_excess(model), e))
    return model.cache[key]


def generator_torque(rows: BallRows, F_ball: np.ndarray) -> float:
    """Torque the balls put on the cam, N mm, counter-clockwise positive.

    A ball's moment on the rim is ``-F A_rot`` (the rows' convention: ``A' F`` balances the torque applied to
    the rim), so the cam takes ``+F A_rot``: the cam's slope under each ball is its lever.
    """
    return float((F_ball * rows.A[:, 2]).sum())
