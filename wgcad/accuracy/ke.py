"""Kinematic error and lost motion of a real drive from tooth contact, no load (docs/models.md 6.2, 7).

At each generator angle the flexspline (rigid gear fixed) is turned as a
rigid body until a tooth touches its rigid neighbour: ``delta_w`` towards the
working flanks, ``delta_n`` towards the others; their sum is the lost motion.
Where it is positive (backlash) the output under a light load sits on the
working flanks, ``theta = s_w delta_w``; where it is negative the teeth
interfere (a preloaded mesh) and the rigid-body position splits the
interference between the flanks, ``theta = s_w (delta_w - delta_n) / 2``
(double-flank engagement, docs/models.md 6.1). Both read
``theta = s_w (delta_w - min(LM, 0) / 2)``. The KE is
``F(phi_h) = phi_h / u_hg - (phi_out - phi_out0) = -(theta - theta_0)``
over one flexspline revolution.

What is exploited (tested against the direct computation in tests/test_ke.py):

* **lattice**: with generator angles on a grid of ``N`` per mesh period, the
  teeth's angles from the major axis fall on a fixed lattice of ``N z_g``
  angles (docs/models.md 7), so the contacts of the perfect drive (with the
  cam-borne offset, constant in the generator frame) are computed once, at
  exactly those angles: no interpolation;
* **linear errors**: run-out, eccentricities and the flexspline-borne and
  stationary cam offsets move the teeth by tens of micrometres; their effect
  on a contact's closing rotation is ``(u_b - u_f) . nt`` with ``nt`` stored
  per contact (:mod:`wgcad.clearance.closing`);
* **second features**: where those errors carry a contact onto another
  feature (a tip running past the end of the other's involute into its root
  fillet: D4 at the major axis) the closing rotation is the lower of the
  features' lines; each pair is solved again with its flexspline tooth moved
  radially within the errors' reach and the other features' lines join the
  candidates;
* **pruning**: a contact whose perfect closing rotation exceeds the best of
  its lattice class by more than both error bounds can never be the first;
* **harmonics**: every error is a first harmonic over the teeth or the
  generator angle, so each contact's error terms are ``Re(A_e . w(i))``
  with three waves of modulus 1 shared by every contact; a contact that
  stays above another of its class by more than their coefficients'
  difference, ``g_e - g_d > sum |A_e - A_d|``, is never first, and the
  handful left are evaluated at every sample
  (:func:`wgcad.accuracy.ke_lanes.first_contacts`; ``reference=True``: the
  older search, block by block among the lanes whose chord can come lowest,
  :func:`wgcad.accuracy.ke_lanes.lane_minimum`; the same minimum);
* **installation angles**: the coefficients depend on an installation
  angle ``gamma`` as ``A + X cos(gamma) + Y sin(gamma)``; ``X`` and ``Y``
  are computed once.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numpy as np

from wgcad.units import ARCSEC_PER_RAD

from ..clearance.closing import closing_direct
from ..errors import DesignError, ModelError
from ..kinematics import gear_ratios
from ..placement.imperfect import Imperfections
from .ke_lanes import LanePlan, candidate_lanes, first_contacts, harmonics, lane_minimum
from .ke_table import DEFAULT_N, ContactTable, contact_table

#: generator angles per pass (a few MB of temporaries per lattice class)
_SPAN = 1 << 16

__all__ = [
    "ContactTable",
    "contact_table",
    "KEResult",
    "kinematic_error",
    "install_angle_scan",
    "optimize_install_angle",
    "closing_direct",
    "spectrum",
    "expected_orders",
    "DEFAULT_N",
    "DEEP_OVERLAP",
]


def _side_coeffs(tab, side, imp, lever):
    """The harmonic coefficients (:func:`wgcad.accuracy.ke_lanes.harmonics`) of one side: of every error group but
    the lever's, and, with a lever, of its group at installation angles 0 and 90 deg (``X``, ``Y``)."""
    groups = tuple(g for g in ("cam", "rigid", "flex") if g != lever)
    A = harmonics(tab, side, imp, groups)
    if lever is None:
        return A, None, None
    key = "rigid_install" if lever == "rigid" else "flex_install"
    return (
        A,
        harmonics(tab, side, imp.replace(**{key: 0.0}), (lever,)),
        harmonics(tab, side, imp.replace(**{key: 0.5 * pi}), (lever,)),
    )


#: closing rotation (rad, negative: turning back) of the first contact's perfect pair beyond which the linear
#: model is not trusted: 300 arcsec. Measured on D2 against the direct computation (exact poses, fresh
#: contact search; 250 samples, each section alone, [S4] errors and 0.3 of them): first contacts whose pair
#: is apart were within 0.5''; turning back by up to 300'' within 1.8''; by more than 600'' (the open end
#: with the full [S4] errors) up to 650'' off, median 38''. The separating feature of so deep an overlap
#: changes with the errors. 300..600'' were not met.
DEEP_OVERLAP = 300.0 / ARCSEC_PER_RAD


def _theta(tab, dw, dn):
    """``theta = s_w (delta_w - min(LM, 0) / 2)`` and the lost motion ``LM`` (in place: no temporaries)."""
    lm = dw + dn
    theta = np.minimum(lm, 0.0)
    theta *= 0.5
    np.subtract(dw, theta, out=theta)
    theta *= tab.side_w
    return theta, lm


@dataclass(slots=True)
class KEResult:
    """No-load KE over a flexspline revolution (radians; arrays over the generator angles)."""

    phi_h: np.ndarray
    delta_w: np.ndarray
    delta_n: np.ndarray
    lost_motion: np.ndarray
    ke: np.ndarray
    n_per_mesh: int
    turns: float
    engagement: str
    u: float
    #: fraction of the samples whose first contact (either side) is a pair that, perfect, overlaps so deeply
    #: that it must turn back by more than :data:`DEEP_OVERLAP` to separate: there the linear model can
    #: be off by hundreds of arcseconds (the separating feature changes with the errors)
    deep_overlap_fraction: float = 0.0

    @property
    def flex_turns_per_record(self) -> float:
        """Flexspline revolutions the record covers (1 for a full record)."""
        return self.turns / self.u

    @property
    def ke_pp(self) -> float:
        """Largest KE: max minus min of F over the record, rad."""
        return float(self.ke.max() - self.ke.min())


def _record(tab: ContactTable) -> int:
    u = abs(gear_ratios(tab.z_g, tab.z_b)["u_hg"])
    return int(np.ceil(tab.N * tab.z_b * u - 1e-9))


def kinematic_error(
    drive,
    imp: Imperfections,
    n_per_mesh: int = DEFAULT_N,
    sections=None,
    table=None,
    samples: int | None = None,
    reference: bool = False,
) -> KEResult:
    """No-load KE of an imperfect drive over one flexspline revolution (``|u_hg|`` generator turns).

    Parameters
    ----------
    table : ContactTable, optional
        Reused if given (it must have been built with the same cam-borne offset).
    samples : int, optional
        Only the first ``samples`` generator angles (tests); default the revolution.
    reference : bool
        The first contacts by the block-by-block search (module docstring; tests hold the default to it).
    """
    tab = table if table is not None else contact_table(drive, imp, n_per_mesh, sections)
    if tab.cam_cam != (imp.cam_cam, imp.cam_cam_phase):
        raise DesignError("imperfections.cam_offset_cam_um", "the contact table was built for another cam-borne offset")
    I = _record(tab) if samples is None else int(samples)
    _require_contacts(tab)
    dw, dn, deep = (_first_contacts_blocks if reference else _first_contacts)(tab, imp, I)
    if I and not (dw.max() < np.inf and dn.max() < np.inf):  # inf where no contact (NaN fails it too)
        free = int(np.count_nonzero(~(np.isfinite(dw) & np.isfinite(dn))))
        raise ModelError(
            f"the flexspline turns freely at {free} of {I} generator angles (no tooth within reach of a rigid tooth "
            "on one side): the output is not driven there and has no KE; check the tooth heights and W0 (wgcad audit)"
        )
    theta, lm = _theta(tab, dw, dn)
    phi_h = np.arange(I) * (2 * tab.sigma) * pi  # sigma i 2 pi / (z_b N), the same products in fewer passes
    phi_h /= tab.z_b * tab.N
    if not I:
        eng = "none (no samples)"
    else:
        eng = "single-flank (backlash)" if lm.min() >= 0 else "double-flank (interference)" if lm.max() < 0 else "mixed"
    if I:
        np.subtract(theta, theta[0], out=theta)
    return KEResult(
        phi_h,
        dw,
        dn,
        lm,
        np.negative(theta, out=theta),
        tab.N,
        I / (tab.N * tab.z_b),
        eng,
        abs(gear_ratios(tab.z_g, tab.z_b)["u_hg"]),
        float(deep.mean()) if I else 0.0,
    )


def _first_contacts(tab: ContactTable, imp: Imperfections, I: int):
    """``delta_w``, ``delta_n`` (inf where no contact) and where either first contact overlaps deeply, over samples
    ``0 .. I - 1``: the undominated lanes at every sample (:func:`wgcad.accuracy.ke_lanes.first_contacts`)."""
    sides = []
    for side in (tab.side_w, -tab.side_w):
        g = tab.sides[side]["g"]
        lanes = candidate_lanes(tab, side, imp)
        e = np.unique(lanes[lanes >= 0])
        A = np.zeros((len(g), 3), dtype=complex)
        A[e] = harmonics(tab, side, imp, contacts=e)  # the lanes' rows only
        sides.append((lanes, g, A, g < -DEEP_OVERLAP))
    (dw, fw), (dn, fn) = first_contacts(tab, sides, I)
    return dw, dn, fw | fn


def _first_contacts_blocks(tab: ContactTable, imp: Imperfections, I: int):
    """What :func:`_first_contacts` computes, by :func:`wgcad.accuracy.ke_lanes.lane_minimum` in passes of
    :data:`_SPAN` samples (the reference)."""
    lw, ln = candidate_lanes(tab, tab.side_w, imp), candidate_lanes(tab, -tab.side_w, imp)
    dw, dn = np.empty(I), np.empty(I)
    deep = np.zeros(I, dtype=bool)
    co = {s: harmonics(tab, s, imp) for s in (tab.side_w, -tab.side_w)}
    for a in range(0, I, _SPAN):
        i = np.arange(a, min(I, a + _SPAN))
        for side, lanes, out in ((tab.side_w, lw, dw), (-tab.side_w, ln, dn)):
            g = tab.sides[side]["g"]
            out[a : a + len(i)], e = lane_minimum(tab, lanes, g, co[side], i)
            deep[a : a + len(i)] |= (e >= 0) & (g[np.maximum(e, 0)] < -DEEP_OVERLAP)
    return dw, dn, deep


def _require_contacts(tab: ContactTable) -> None:
    """Refuse a drive whose teeth never come within reach of each other (:class:`~wgcad.errors.ModelError`)."""
    for side in (tab.side_w, -tab.side_w):
        if not len(tab.sides[side]["g"]):
            which = "working" if side == tab.side_w else "non-working"
            raise ModelError(
                f"no tooth of the flexspline comes within reach of a rigid tooth on its {which} side at any generator "
                "angle: the output is not driven and has no KE; check the tooth heights, the shifts and W0 (wgcad audit)"
            )


def install_angle_scan(tab: ContactTable, imp: Imperfections, angles, lever: str = "rigid") -> np.ndarray:
    """Largest KE (rad) for each installation angle (rad) of the rigid gear (``lever="rigid"``) or the flexspline."""
    if lever not in ("rigid", "flex"):
        raise DesignError("lever", f"must be rigid or flex, got {lever!r}")
    ang = np.atleast_1d(np.asarray(angles, dtype=float))
    ca, sa = np.cos(ang), np.sin(ang)
    I = _record(tab)
    _require_contacts(tab)
    lw, ln = (
        candidate_lanes(tab, tab.side_w, imp),
        candidate_lanes(tab, -tab.side_w, imp),
    )  # the bounds hold for every angle
    hi = np.full(len(ang), -np.inf)
    lo = np.full(len(ang), np.inf)
    cw, cn = _side_coeffs(tab, tab.side_w, imp, lever), _side_coeffs(tab, -tab.side_w, imp, lever)
    gw, gn = tab.sides[tab.side_w]["g"], tab.sides[-tab.side_w]["g"]
    for a in range(0, I, _SPAN):
        i = np.arange(a, min(I, a + _SPAN))
        pw, pn = LanePlan(tab, lw, i), LanePlan(tab, ln, i)
        for k in range(len(ang)):
            # an installation angle turns the lever's errors: base + X cos + Y sin, harmonics and all
            dw = lane_minimum(tab, lw, gw, cw[0] + ca[k] * cw[1] + sa[k] * cw[2], i, plan=pw)[0]
            dn = lane_minimum(tab, ln, gn, cn[0] + ca[k] * cn[1] + sa[k] * cn[2], i, plan=pn)[0]
            th, _ = _theta(tab, dw, dn)
            hi[k] = max(hi[k], th.max())
            lo[k] = min(lo[k], th.min())
    return hi - lo


def optimize_install_angle(tab: ContactTable, imp: Imperfections, lever: str = "rigid", n_grid: int = 36):
    """Installation angle (rad) that minimises the largest KE: a grid of ``n_grid`` angles, then finer grids (1/10, 1/100 of its step) around the three best local minima.

    Returns
    -------
    best_angle : float
        rad, in [0, 2 pi).
    best_pp : float
        Largest KE there, rad.
    grid, grid_pp : (n_grid,) float
        The coarse scan (the curve of the largest KE against the angle).
    """
    grid = 2 * pi * np.arange(n_grid) / n_grid
    pp = install_angle_scan(tab, imp, grid, lever)
    # the curve can have several basins of similar depth: refine around the three best local minima
    loc = [i for i in range(n_grid) if pp[i] <= pp[i - 1] and pp[i] <= pp[(i + 1) % n_grid]]
    starts = sorted(loc, key=lambda i: pp[i])[:3] or [int(np.argmin(pp))]
    step0 = 2 * pi / n_grid
    fine = np.concatenate([grid[i] + np.linspace(-step0, step0, 21) for i in starts])
    v = install_angle_scan(tab, imp, fine, lever)
    best_a, best_v = float(fine[int(np.argmin(v))]), float(v.min())
    fine = best_a + np.linspace(-step0 / 10, step0 / 10, 21)
    v = install_angle_scan(tab, imp, fine, lever)
    if v.min() < best_v:
        best_a, best_v = float(fine[int(np.argmin(v))]), float(v.min())
    return best_a % (2 * pi), best_v, grid, pp


def spectrum(res: KEResult):
    """Amplitude spectrum of the KE over the record: orders (cycles per record) and amplitudes (rad)."""
    f = res.ke - res.ke.mean()
    amp = 2.0 * np.abs(np.fft.rfft(f)) / len(f)
    return np.arange(len(amp)) * (res.flex_turns_per_record**-1), amp


def expected_orders(z_g: int, z_b: int) -> dict:
    """Orders (cycles per flexspline revolution) where the errors should show (docs/models.md 6.1, 7).

    Rigid gear and stationary cam offset: once per generator turn, ``|u_hg|``;
    flexspline and flexspline-borne offset: ``|u_hb|``; the no-load contact
    takes the first zone to touch, which rectifies them (twice those); the
    mesh: ``z_b |u_hg|``.
    """
    r = gear_ratios(z_g, z_b)
    uh, ub = abs(r["u_hg"]), abs(r["u_hb"])
    return {"rigid": uh, "flex": ub, "rigid x2": 2 * uh, "flex x2": 2 * ub, "mesh": z_b * uh}
