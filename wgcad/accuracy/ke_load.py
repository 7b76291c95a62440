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

from dataclasses import dataclass, field
from math import pi

import numpy as np

from ..errors import DesignError
from ..kinematics import gear_ratios
from ..placement.imperfect import Imperfections
from .load_errors import tooth_errors
from .states import StateJob, solve_states

__all__ = [
    "LoadedKE",
    "SINGLE_ZONE_SHARE",
    "sample_periods",
    "tooth_errors",
    "loaded_ke",
    "LoadedLever",
    "install_lever",
    "SCAN_ANGLES",
]


#: a load state is single-zone when the lesser engagement zone carries less than this share of the tooth torque
#: ([S4]: single-zone engagement, which the errors cause, is what raises the KE; docs/models.md 6.3)
SINGLE_ZONE_SHARE = 0.05


@dataclass(slots=True)
class LoadedKE:
    """Loaded KE at whole mesh periods (radians; arrays over the samples)."""

    torque_nm: float
    periods: np.ndarray  #: mesh periods n of each sample
    phi_h: np.ndarray  #: generator angle, rad
    theta: np.ndarray  #: output rotation against the rigid gear, rad (counter-clockwise)
    ke: np.ndarray  #: -(theta - theta[0])
    wind_up: float  #: mean rotation (mesh wind-up) over the samples, rad
    teeth_in_contact: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    seconds: float = 0.0
    #: each sample's share of the tooth torque carried by each engagement zone, ``(n, waves)``
    zone_share: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))

    @property
    def ke_pp(self) -> float:
        return float(self.ke.max() - self.ke.min())

    @property
    def single_zone(self) -> np.ndarray:
        """Which samples are single-zone (the lesser zone below :data:`SINGLE_ZONE_SHARE` of the tooth torque)."""
        if self.zone_share.size == 0:
            return np.zeros(len(self.ke), dtype=bool)
        return np.nanmin(self.zone_share, axis=1) < SINGLE_ZONE_SHARE

    @property
    def single_zone_fraction(self) -> float:
        return float(self.single_zone.mean()) if len(self.ke) else 0.0

    def ke_range(self, mask: np.ndarray) -> float:
        """Peak to peak of the KE over the samples ``mask`` (0 for fewer than two), rad."""
        k = self.ke[mask]
        return float(k.max() - k.min()) if k.size >= 2 else 0.0


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


def loaded_ke(
    drive,
    imp: Imperfections,
    torque_nm: float,
    samples: int | None = None,
    model=None,
    progress=None,
    tol: float | None = None,
    workers: int | None = None,
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
    workers : int, optional
        Processes to share the states among (:mod:`wgcad.accuracy.states`; default the cores available); the
        figures do not depend on it.
    """
    import time

    from ..elastic import build_model

    d = drive.design.drive
    _check(d, torque_nm)
    t0 = time.perf_counter()
    model = build_model(drive) if model is None else model
    periods = sample_periods(d.z_flex, d.z_rigid, samples)
    run = solve_states(model, [StateJob(imp, float(torque_nm), periods, tol)], workers, progress)[0]
    return _loaded(model, torque_nm, periods, run, time.perf_counter() - t0)


def _check(d, torque_nm) -> None:
    if d.fixed != "rigid":
        raise DesignError("drive.fixed", f"the loaded KE models a fixed rigid gear, flexspline output; got '{d.fixed}'")
    if not (np.isfinite(torque_nm) and torque_nm > 0):
        raise DesignError("--torque-nm", f"must be > 0 N m for the loaded KE, got {torque_nm:g}")


def _loaded(model, torque_nm, periods, run, seconds) -> LoadedKE:
    d = model.drive.design.drive
    sigma = 1 if d.rotation == "ccw" else -1
    phi_h = sigma * periods * 2.0 * pi / d.z_rigid
    theta = run.theta
    return LoadedKE(
        float(torque_nm),
        periods,
        phi_h,
        theta,
        -(theta - theta[0]),
        float(model.torque_sign * theta.mean()),
        run.teeth,
        seconds,
        run.share,
    )


#: installation angles of the loaded scan's coarse grid (20 deg): the largest KE under load against the angle
#: is a smooth curve of one or two lobes ([S4] Fig. 3; D2 at 80 and 800 N m: one), so 18 angles find its basin
SCAN_ANGLES = 18


@dataclass(slots=True)
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
    workers: int | None = None,
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
    _check(d, torque_nm)
    u = abs(gear_ratios(d.z_flex, d.z_rigid)["u_hg"])
    scan_samples = int(np.ceil(u) + 4) if scan_samples is None else int(scan_samples)
    scan_p = sample_periods(d.z_flex, d.z_rigid, scan_samples)
    full_p = sample_periods(d.z_flex, d.z_rigid, samples)
    total = (n_grid + 2) * len(scan_p) + (1 if design is not None else 2) * len(full_p)
    done = [0]

    def tick(i, n):
        if progress is not None:
            progress(done[0] + i, total)

    def ke_at(angles, periods):
        jobs = [StateJob(imp.replace(rigid_install=float(a)), float(torque_nm), periods) for a in angles]
        runs = solve_states(model, jobs, workers, tick)
        done[0] += len(jobs) * len(periods)
        return [_loaded(model, torque_nm, periods, r, 0.0) for r in runs]

    grid = 2 * pi * np.arange(n_grid) / n_grid
    pp = np.array([L.ke_pp for L in ke_at(grid, scan_p)])
    i = int(np.argmin(pp))
    step = 2 * pi / n_grid
    extra = [grid[i] - step / 2, grid[i] + step / 2]
    pe = [L.ke_pp for L in ke_at(extra, scan_p)]
    cands = [(pp[i], grid[i])] + list(zip(pe, extra))
    best_angle = float(min(cands)[1]) % (2 * pi)
    if design is None:
        best, design = ke_at([best_angle, imp.rigid_install], full_p)
    else:
        (best,) = ke_at([best_angle], full_p)
    if not best.ke_pp < design.ke_pp:
        # the scan ranks on fewer states: where its best does no better than the design's own angle on every
        # state, the design's angle is the answer (a flat curve: the lever does nothing)
        best_angle, best = float(imp.rigid_install) % (2 * pi), design
    return LoadedLever(float(torque_nm), grid, pp, best_angle, best, design, scan_samples, time.perf_counter() - t0)
