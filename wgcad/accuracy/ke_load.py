"""Kinematic error under load: the elastic contact model of the imperfect drive at whole mesh periods of the generator (docs/models.md 6.3).

The elastic model (:func:`wgcad.elastic.solve_load`) solves the
loaded drive with the generator at angle 0. At a generator angle that is a
whole number ``n`` of mesh periods, ``phi_h = sigma n 2 pi / z_b``, a perfect
drive looks exactly the same in the generator's frame (docs/models.md 7):
flexspline tooth ``q`` of the model is the drive's tooth ``k = q + sigma n``,
rigid position ``p`` its tooth ``j = p + sigma n``. An imperfect drive then
differs only by its errors, which are known for those teeth and that angle,
and are put into the model as it solves:

* the cam mounting error (all three components, in the generator's frame)
  is the model's cam offset: the rim follows it through the balls;
* each flexspline tooth's run-out and eccentricity move it along its rim
  (a turn about the axis by ``dalpha``) and along its axis (``drho``);
* the rigid gear's eccentricity and each rigid tooth's run-out turn enter as
  the opposite motion of the flexspline teeth facing them (only the
  relative position of a pair matters to its contact).

The loaded KE is ``-(theta(phi_h) - theta(0))`` with ``theta`` the rim's
rotation against the rigid gear, over samples spread along a flexspline
revolution; between whole mesh periods the model has no state, so the
loaded KE is sampled, not followed within a mesh period.
"""

from __future__ import annotations

from dataclasses import field
from math import pi

import numpy as np

from ..errors import DesignError
from ..kinematics import gear_ratios
from ..placement.imperfect import Imperfections, cam_offset, flex_deviations, rigid_translation
from ..records import record

__all__ = ["LoadedKE", "sample_periods", "tooth_errors", "loaded_ke", "LoadedLever", "install_lever", "SCAN_ANGLES"]


@record
class LoadedKE:
    """Loaded KE at whole mesh periods (radians; arrays over the samples)."""

    torque_nm: float
    periods: np.ndarray  #: mesh periods n of each sample
    phi_h: np.ndarray  #: generator angle, rad
    theta: np.ndarray  #: rim rotation against the rigid gear, rad (counter-clockwise)
    ke: np.ndarray  #: -(theta - theta[0])
    wind_up: float  #: mean rotation (mesh wind-up) over the samples, rad
    teeth_in_contact: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    seconds: float = 0.0

    @property
    def ke_pp(self) -> float:
        return float(self.ke.max() - self.ke.min())


def sample_periods(z_g: int, z_b: int, samples: int | None = None) -> np.ndarray:
    """Mesh periods ``n`` (whole numbers) spread evenly over a flexspline revolution (``|u_hg| z_b`` of them).

    By default ``4 |u_hg| + 4``: the cam's errors repeat ``|u_hg|`` times a
    revolution and the contact rectifies them (``2 |u_hg|``, docs/models.md
    6.2); more than twice that order is sampled. Whole mesh periods fall at
    other phases of each cam turn, so the samples are a stroboscopic view of
    the cam-order content, not a curve through it.
    """
    u = abs(gear_ratios(z_g, z_b)["u_hg"])
    total = int(round(u * z_b))
    if samples is None:
        samples = int(4 * np.ceil(u) + 4)
    samples = int(min(max(samples, 2), total))
    return np.unique(np.round(np.linspace(0.0, total, samples, endpoint=False)).astype(int))


def tooth_errors(model, imp: Imperfections, n: int):
    """The errors of the drive at ``n`` mesh periods as the model's inputs: ``(turn, move)`` per tooth and the cam offset.

    Returns
    -------
    (turn (S z_g,), move (S z_g, 2)), cam_offset_um, cam_offset_deg
    """
    drive = model.drive
    d = drive.design.drive
    z_g, z_b = d.z_flex, d.z_rigid
    sigma = 1 if d.rotation == "ccw" else -1
    phi_h = sigma * n * 2.0 * pi / z_b
    phi_g = phi_h / gear_ratios(z_g, z_b)["u_hg"]
    q = np.arange(z_g)
    k = (q + sigma * n) % z_g  # the drive's tooth at the model's position q
    dalpha, drho = flex_deviations(imp, k, z_g, drive.flex.r)
    ang = model.tables.angles[:z_g]  # the model's tooth angles (generator frame)
    # the rigid tooth facing each flexspline tooth: its run-out turn, read continuously along the gear
    # (exact at tooth centres; adjacent teeth differ by F_b/(2 r_b) 2 pi/z_b, far below a micrometre)
    a_rigid = ang + phi_h
    dev = (0.5 * imp.rigid_runout / drive.rigid.r) * np.sin(a_rigid - imp.rigid_install + imp.rigid_runout_phase)
    c, s = np.cos(-phi_h), np.sin(-phi_h)
    T = rigid_translation(imp)
    T = np.array([c * T[0] - s * T[1], s * T[0] + c * T[1]])  # the rigid gear's shift in the generator frame
    turn = dalpha - dev
    # the tooth's axis after the turn: drho along it (the rim's own rotation there is theta, ~1e-2 rad: its
    # effect on a micrometre-sized drho is far below the figures)
    axis = np.stack([np.cos(ang + turn), np.sin(ang + turn)], axis=-1)
    move = drho[:, None] * axis - T[None, :]
    S = len(model.zs)
    E = cam_offset(imp, phi_h, phi_g)
    Eg = np.array([c * E[0] - s * E[1], s * E[0] + c * E[1]])
    return (
        (np.tile(turn, S), np.tile(move, (S, 1))),
        1e3 * float(np.hypot(*Eg)),
        float(np.degrees(np.arctan2(Eg[1], Eg[0]))),
    )


def loaded_ke(
    drive,
    imp: Imperfections,
    torque_nm: float,
    samples: int | None = None,
    model=None,
    progress=None,
    tol: float | None = None,
) -> LoadedKE:
    """The KE of an imperfect drive under ``torque_nm`` from the elastic model at whole mesh periods (module docstring).

    Parameters
    ----------
    samples : int, optional
        Load states over the flexspline revolution (default :func:`sample_periods`'s).
    model : ElasticModel, optional
        Reused if given (:func:`wgcad.elastic.build_model`).
    progress : callable, optional
        ``progress(done, total)``.
    tol : float, optional
        The elastic solve's position tolerance, mm (default its own, 0.2 um: about 0.5'' of rotation at
        80 mm; the tests tighten it to compare two routes).
    """
    import time

    from ..elastic import build_model, solve_load

    d = drive.design.drive
    if d.fixed != "rigid":
        raise DesignError("drive.fixed", f"the loaded KE models a fixed rigid gear, flexspline output; got '{d.fixed}'")
    if not (np.isfinite(torque_nm) and torque_nm > 0):
        raise DesignError("--torque-nm", f"must be > 0 N m for the loaded KE, got {torque_nm:g}")
    t0 = time.perf_counter()
    model = build_model(drive) if model is None else model
    periods = sample_periods(d.z_flex, d.z_rigid, samples)
    theta = np.empty(len(periods))
    teeth = np.empty(len(periods), dtype=int)
    warm = None
    for i, n in enumerate(periods):
        errs, e_um, e_deg = tooth_errors(model, imp, int(n))
        kw = {} if tol is None else {"tol": tol}
        st = solve_load(model, float(torque_nm), e_um, e_deg, warm=warm, tooth_errors=errs, **kw)
        theta[i] = float(st.rigid[2])
        c = st.contacts
        teeth[i] = int(np.count_nonzero((c["kind"] == 1) & (c["force"] > 0)))
        warm = st
        if progress is not None:
            progress(i + 1, len(periods))
    sigma = 1 if d.rotation == "ccw" else -1
    phi_h = sigma * periods * 2.0 * pi / d.z_rigid
    return LoadedKE(
        float(torque_nm),
        periods,
        phi_h,
        theta,
        -(theta - theta[0]),
        float(model.torque_sign * theta.mean()),
        teeth,
        time.perf_counter() - t0,
    )


#: installation angles of the loaded scan's coarse grid (20 deg): the largest KE under load against the angle
#: is a smooth curve of one or two lobes ([S4] Fig. 3; D2 at 80 and 800 N m: one), so 18 angles find its basin
SCAN_ANGLES = 18


@record
class LoadedLever:
    """The rigid gear's installation angle under load (radians inside).

    Attributes
    ----------
    torque_nm : float
    grid : (G,) float
        Installation angles of the scan, rad.
    grid_pp : (G,) float
        Largest KE at each, rad, from ``scan_samples`` load states each (a ranking: fewer states than the
        final figures, so a little lower).
    best_angle : float
        The angle of the smallest largest KE, rad (the scan's best, refined between its neighbours).
    best : LoadedKE
        The KE there, from the full sampling.
    design : LoadedKE
        The KE at the design's own installation angle, full sampling.
    scan_samples : int
    seconds : float
    """

    torque_nm: float
    grid: np.ndarray
    grid_pp: np.ndarray
    best_angle: float
    best: LoadedKE
    design: LoadedKE
    scan_samples: int
    seconds: float

    @property
    def lever(self) -> float:
        """How many times the best angle lowers the design's largest KE."""
        return self.design.ke_pp / self.best.ke_pp if self.best.ke_pp > 0 else float("inf")


def install_lever(
    drive,
    imp: Imperfections,
    torque_nm: float,
    model=None,
    samples: int | None = None,
    scan_samples: int | None = None,
    n_grid: int = SCAN_ANGLES,
    progress=None,
    design: LoadedKE | None = None,
) -> LoadedLever:
    """The rigid gear's installation angle that lowers the largest KE under ``torque_nm`` most ([S4], docs/models.md 6.3).

    Each angle turns the rigid gear's error pattern (its run-out) against the
    stationary errors; the loaded KE is the elastic model's at whole mesh
    periods (:func:`loaded_ke`). The grid of ``n_grid`` angles is ranked with
    ``scan_samples`` states each (default ``|u_hg| + 4``: a stroboscopic pass
    over every cam phase), the best refined at two angles between its
    neighbours, and the best and the design's own angle evaluated with the
    full ``samples`` (``design``: the latter when already computed); the
    design's angle is the best unless the other is lower there.
    ``progress(done, total)`` counts load states.
    """
    import time

    from ..elastic import build_model

    t0 = time.perf_counter()
    model = build_model(drive) if model is None else model
    d = drive.design.drive
    u = abs(gear_ratios(d.z_flex, d.z_rigid)["u_hg"])
    scan_samples = int(np.ceil(u) + 4) if scan_samples is None else int(scan_samples)
    n_scan = len(sample_periods(d.z_flex, d.z_rigid, scan_samples))
    n_full = len(sample_periods(d.z_flex, d.z_rigid, samples))
    total = (n_grid + 2) * n_scan + (1 if design is not None else 2) * n_full
    done = [0]

    def tick(i, n):
        if progress is not None:
            progress(done[0] + i, total)

    def ke_at(angle, ns):
        L = loaded_ke(drive, imp.replace(rigid_install=float(angle)), torque_nm, samples=ns, model=model, progress=tick)
        done[0] += len(L.ke)
        return L

    grid = 2 * pi * np.arange(n_grid) / n_grid
    pp = np.array([ke_at(a, scan_samples).ke_pp for a in grid])
    i = int(np.argmin(pp))
    step = 2 * pi / n_grid
    extra = [grid[i] - step / 2, grid[i] + step / 2]
    pe = [ke_at(a, scan_samples).ke_pp for a in extra]
    cands = [(pp[i], grid[i])] + list(zip(pe, extra))
    best_angle = float(min(cands)[1]) % (2 * pi)
    best = ke_at(best_angle, samples)
    design = ke_at(imp.rigid_install, samples) if design is None else design
    if not best.ke_pp < design.ke_pp:
        # the scan ranks on fewer states: where its best does no better than the design's own angle on every
        # state, the design's angle is the answer (a flat curve: the lever does nothing)
        best_angle, best = float(imp.rigid_install) % (2 * pi), design
    return LoadedLever(float(torque_nm), grid, pp, best_angle, best, design, scan_samples, time.perf_counter() - t0)
