"""The perfect drive's contact table for the kinematic error: every tooth pair's closing rotation on a lattice of tooth angles, with its sensitivities to the errors (docs/models.md 6.2, 7).

Built once per drive (and cam-borne offset); :mod:`wgcad.accuracy.ke`
computes a KE from it for any other errors. A pair's contact is solved on
the exact poses, its sensitivities by central differences; where the
errors' radial reach can move a contact onto another surface (a tip into
the root fillet) that surface is tabulated too (``_second_features``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import pi

import numpy as np

from wgcad.units import ARCSEC_PER_RAD

from ..clearance.closing import closing_rotation
from ..clearance.distance import Template
from ..errors import DesignError
from ..kinematics import gear_ratios
from ..placement import tooth_pose
from ..placement.imperfect import Imperfections, cam_offset, coning_factor
from .ke_lanes import candidate_lanes, fold_angle

__all__ = ["ContactTable", "contact_table", "DEFAULT_N", "NT_MAX"]

#: generator angles per mesh period (2 pi / z_b); benchmarks/ke.py measures the error of
#: 16 against 160: it is what keeps the full D2 revolution (323 200 angles) within seconds
DEFAULT_N = 16
_CHUNK = 8192
#: contacts whose closing-rotation sensitivity |nt| exceeds this over the pitch radius are dropped:
#: the contact normal is within 14 deg of radial (a tip grazing a root), a rotation hardly closes
#: the gap, and a few micrometres of radial error change it by arcminutes (the linear model fails)
NT_MAX = 2.0


@dataclass
class ContactTable:
    """Contacts of the perfect drive (plus the cam-borne offset) on the tooth-angle lattice, per side.

    ``sides[s]`` (s = +1: counter-clockwise, towards the rigid tooth above)
    holds arrays over the contacts found: lattice index ``m``, ``g``
    (closing rotation, rad), ``nt`` (E, 2), ``a_phi``, ``a_rho``, ``a_beta``
    (sensitivities to a tooth's along-rim shift, radial offset, and a rigid
    tooth's rotation), ``j`` (rigid tooth, table frame), ``c`` (coning factor).
    """

    z_g: int
    z_b: int
    N: int
    sections: list
    side_w: int
    sigma: int
    r_g: float
    r_b: float
    cam_cam: tuple
    sides: dict = field(default_factory=dict)


def _check(drive):
    d = drive.design.drive
    if d.fixed != "rigid":
        raise DesignError(
            "drive.fixed",
            f"wgcad ke models a fixed rigid gear, flexspline output (docs/models.md 6.2); got '{d.fixed}'",
        )


def contact_table(
    drive,
    imp: Imperfections,
    n_per_mesh: int = DEFAULT_N,
    sections=None,
    reach_pitches: float = 0.5,
    exhaustive: bool = False,
    progress=None,
) -> ContactTable:
    """Tabulate every tooth's contact on both sides at the ``N z_g`` lattice angles (module docstring).

    Parameters
    ----------
    drive : wgcad.drive.Drive
    imp : Imperfections
        Only the cam-borne offset enters the table (exactly); the rest is linear.
    n_per_mesh : int
        Generator angles per mesh period, N.
    sections : list of float or None
        Axial sections (mm from the open end); default the three of the audit
        (ends and middle) with coning, one without.
    reach_pitches : float
        Contacts that need a rotation beyond this many flexspline pitches are dropped.
    exhaustive : bool
        Search every solved pair for second features, each search from rest
        (the reference tests/test_ke.py compares with); by default only the
        pairs that can be first (:func:`_can_be_first`), each search started
        where the pair's own line puts the moved contact.
    progress : callable, optional
        ``progress(fraction)`` after each section and side of each stage
        (fractions from the stages' times on D2).
    """
    tick = progress or (lambda f: None)
    _check(drive)
    if not isinstance(n_per_mesh, int) or n_per_mesh < 1:
        raise DesignError("n_per_mesh", f"must be a positive whole number, got {n_per_mesh!r}")
    d = drive.design.drive
    z_g, z_b = d.z_flex, d.z_rigid
    if sections is None:
        sections = [float(z) for z in drive.sections(3)] if drive.coned else [None]
    u = gear_ratios(z_g, z_b)["u_hg"]
    sigma = 1 if d.rotation == "ccw" else -1
    side_w = 1 if sigma / u < 0 else -1  # the flank facing against the relative motion carries the load
    flex, rigid = Template(drive.flex.tooth_polygon()), Template(drive.rigid.tooth_polygon())
    M = z_g * n_per_mesh
    m_all = np.arange(M)
    phi = fold_angle(2 * pi * m_all / M)
    fa = -phi * z_g / z_b  # generator angle that puts a tooth at phi with its material angle at phi (z_b - z_g)/z_b
    # radial reach of the linear errors (the cam-borne offset is in the table exactly), plus 2 um
    margin = 2e-3 + imp.flex_ecc + imp.rigid_ecc + imp.cam_flex + imp.cam_fixed
    tab = ContactTable(
        z_g,
        z_b,
        n_per_mesh,
        list(sections),
        side_w,
        sigma,
        drive.flex.r,
        drive.rigid.r,
        (imp.cam_cam, imp.cam_cam_phase),
    )
    lat = _Lattice(drive, flex, rigid, m_all, phi, fa, margin, reach_pitches * 2 * pi / z_g)
    parts = {s: [] for s in (1, -1)}
    pending = {s: [] for s in (1, -1)}  # each section's solved pairs, for the second features
    for si, z in enumerate(sections):
        engaged = _engaged(lat, imp, z)
        for side in (1, -1):
            rows, item = _first_contacts(lat, engaged, side)
            parts[side].append(rows)
            pending[side].append(item)
            tick(0.4 * (2 * si + (side < 0) + 1) / (2 * len(sections)))
    # the touching feature can change within the errors' radial reach (a tip reaching past the end of the
    # other's involute into its root fillet): each pair that can be first is solved again with its
    # flexspline tooth moved radially, and the contact found there, carried back to the perfect pose along
    # its own sensitivity, added as a further candidate (_second_features)
    if imp.cam_flex + imp.cam_fixed + imp.flex_ecc + imp.rigid_ecc > 0.0:
        for side in (1, -1):
            tick(0.4 + 0.35 * (side < 0))
            parts[side].extend(_more_features(lat, tab, imp, side, pending[side], exhaustive))
    for side in (1, -1):
        tick(0.75 + 0.125 * (side < 0))
        tab.sides[side] = {key: np.concatenate([p[key] for p in parts[side]]) for key in parts[side][0]}
        _refine(tab, side, imp, flex, rigid, lat.reach)
    tick(1.0)
    return tab


@dataclass(slots=True)
class _Lattice:
    """What every stage of the table shares: the drive, the teeth's outlines, the lattice of tooth angles."""

    drive: object
    flex: Template
    rigid: Template
    m_all: np.ndarray
    phi: np.ndarray  # tooth angle of each lattice point
    fa: np.ndarray  # generator angle that puts a tooth there
    margin: float  # radial reach of the linear errors, mm
    reach: float  # largest closing rotation looked at, rad


def _engaged(lat: _Lattice, imp: Imperfections, z):
    """The lattice points of section ``z`` whose tooth reaches the rigid tip circle (within the errors' reach): their
    indices, poses, pose derivatives along the rim, lower rigid tooth and coning factor."""
    drive, flex = lat.drive, lat.flex
    law = drive.law if z is None else drive.law_at(z)
    cz = coning_factor(drive, z)
    off = cz * cam_offset(imp, lat.fa, 0.0, parts=("cam",))
    rot, shift = tooth_pose(law, lat.phi, drive.r_m, frame_angle=lat.fa)
    shift = shift + off
    # radially engaged (plus the errors' reach): the others cannot touch by turning
    c, s = np.cos(rot), np.sin(rot)
    xs = flex.local[:, 0][None, :] * c[:, None] - flex.local[:, 1][None, :] * s[:, None] + shift[:, :1]
    ys = flex.local[:, 0][None, :] * s[:, None] + flex.local[:, 1][None, :] * c[:, None] + shift[:, 1:]
    R = np.hypot(xs, ys)
    # radially engaged, or within the errors' radial reach of it. A tooth that barely reaches past
    # the rigid tip circle touches with a tip corner, and there a few micrometres of radial error
    # decide whether it touches at all: the linear model holds only for errors well below that
    # overlap (tests/test_ke.py, benchmarks/ke.py measure it against the direct computation)
    over = (drive.rigid.r_a - R.min(axis=1)) if drive.external else (R.max(axis=1) - drive.rigid.r_a)
    idx = np.nonzero(over >= -lat.margin)[0]
    gamma_b = 2 * pi / drive.design.drive.z_rigid
    a = np.arctan2(shift[idx, 1] + drive.r_m * s[idx], shift[idx, 0] + drive.r_m * c[idx])
    lo = np.floor(a / gamma_b - 0.5).astype(int)
    # derivative of the pose along the rim (tooth angle phi, frame fixed): for the along-rim shifts
    h = 1e-6
    rp, sp = tooth_pose(law, lat.phi[idx] + h, drive.r_m, frame_angle=lat.fa[idx])
    rm_, sm = tooth_pose(law, lat.phi[idx] - h, drive.r_m, frame_angle=lat.fa[idx])
    drot, dshift = (rp - rm_) / (2 * h), (sp - sm) / (2 * h)
    return idx, rot, shift, drot, dshift, lo, cz


def _first_contacts(lat: _Lattice, engaged, side: int):
    """The contacts of the engaged teeth turned towards ``side``: the table rows, and what the second features need."""
    idx, rot, shift, drot, dshift, lo, cz = engaged
    drive = lat.drive
    z_b = drive.design.drive.z_rigid
    j = (lo + (1 if side > 0 else 0)) % z_b
    rb = (j + 0.5) * 2 * pi / z_b
    con = closing_rotation(lat.flex, rot[idx], shift[idx], lat.rigid, rb, np.zeros((len(idx), 2)), side, lat.reach)
    good = con.ok & (np.hypot(con.nt[:, 0], con.nt[:, 1]) * drive.rigid.r <= NT_MAX)
    k = np.nonzero(good)[0]
    poses = _Poses(idx, rot, shift, drot, dshift, lat.m_all, j, cz)
    rows = _rows(con, k, poses, side, np.zeros(len(k)))
    return rows, _Solved(rows, k, poses, rb)


def _more_features(lat: _Lattice, tab: ContactTable, imp: Imperfections, side: int, pending: list, exhaustive: bool):
    """The second features of the pairs of one side that can be first (:func:`_second_features`), as table rows."""
    out = []
    keep = (
        np.ones(sum(len(x.k) for x in pending), dtype=bool)
        if exhaustive
        else _can_be_first(tab, side, imp, pending, lat.flex, lat.rigid)
    )
    at = 0
    for sv in pending:
        sub = np.nonzero(keep[at : at + len(sv.k)])[0]
        at += len(sv.k)
        rho = sv.poses.cz * (imp.cam_flex + imp.cam_fixed) + imp.flex_ecc + imp.rigid_ecc
        if rho > 0.0 and sub.size:
            out.extend(_second_features(lat, sv, sub, side, rho, warm=not exhaustive))
    return out


@dataclass(slots=True)
class _Poses:
    """Tooth pairs of the lattice: ``idx`` the lattice points (into ``rot``, ``shift``: the lattice's poses), and per
    pair the pose's derivatives along the rim (``drot``, ``dshift``), the rigid tooth ``j``; the lattice indices
    ``m_all`` and the section's coning factor ``cz``."""

    idx: np.ndarray
    rot: np.ndarray
    shift: np.ndarray
    drot: np.ndarray
    dshift: np.ndarray
    m_all: np.ndarray
    j: np.ndarray
    cz: float

    def take(self, k) -> _Poses:
        """The pairs ``k``."""
        return _Poses(self.idx[k], self.rot, self.shift, self.drot[k], self.dshift[k], self.m_all, self.j[k], self.cz)


@dataclass(slots=True)
class _Solved:
    """One section's and side's first contacts: their table rows, which engaged pairs they are (``k``, into
    ``poses``), and the rigid teeth's angles ``rb`` of the engaged pairs."""

    rows: dict
    k: np.ndarray
    poses: _Poses
    rb: np.ndarray


def _rows(con, k, poses: _Poses, side: int, extra):
    """Table rows of contacts ``k`` of a closing-rotation solve of the pairs ``poses``."""
    idx, rot, shift, drot, dshift, j = poses.idx, poses.rot, poses.shift, poses.drot, poses.dshift, poses.j
    t = side * con.delta[k]
    ct, st = np.cos(t), np.sin(t)
    sh = np.stack([ct * shift[idx[k], 0] - st * shift[idx[k], 1], st * shift[idx[k], 0] + ct * shift[idx[k], 1]], -1)
    ds = np.stack([ct * dshift[k, 0] - st * dshift[k, 1], st * dshift[k, 0] + ct * dshift[k, 1]], -1)
    p, q, nt = con.p[k], con.q[k], con.nt[k]
    dP = drot[k, None] * np.stack([-(p[:, 1] - sh[:, 1]), p[:, 0] - sh[:, 0]], -1) + ds
    rr = rot[idx[k]] + t
    return {
        "m": poses.m_all[idx[k]],
        "g": con.delta[k],
        "nt": nt,
        "a_phi": np.einsum("ij,ij->i", dP, nt),
        "a_rho": np.cos(rr) * nt[:, 0] + np.sin(rr) * nt[:, 1],
        "a_beta": -q[:, 1] * nt[:, 0] + q[:, 0] * nt[:, 1],
        "j": j[k],
        "c": np.full(len(k), poses.cz),
        "dP": dP,
        "rr": rr,
        "q": q,
        "rot": rot[idx[k]],
        "shift": shift[idx[k]],
        "extra": extra,
    }


#: the finite-difference sensitivities (_refine) replace a nearest-point normal only within 50 % of it
_REFINED_NT = 1.5


def _can_be_first(tab: ContactTable, side: int, imp: Imperfections, pending, flex, rigid) -> np.ndarray:
    """Which solved pairs (in the order of ``pending``) can be the first contact of their lattice class under some errors.

    Only those are searched for second features: any other pair's lines,
    found or not, stay above the class's first contact for every error
    within the amplitudes, so the KE is the same with or without them
    (tests/test_ke.py compares against every pair searched).

    Every line of the table changes with the errors by at most
    ``|nt| (V + A_b |q| + A_a |dP| + e_g)`` (the terms of :func:`wgcad.accuracy.ke_lanes.error_terms`, with
    ``|a_beta| <= |q| |nt|``, ``|a_phi| <= |dP| |nt|``, ``|a_rho| <= |nt|``).
    A pair's own line has ``|nt|`` within ``_REFINED_NT`` times its
    nearest-point one (the refined normal is kept only within 50 % of it);
    a second feature's is within ``NT_MAX / r_b`` and starts no lower than
    the pair's own line at the perfect pose (:func:`_second_features` keeps it so);
    ``|q|`` is at most the rigid tooth's largest radius and ``|dP|`` at most
    the tooth's speed along the rim plus its turn times its largest radius.
    So every line of pair ``e`` stays above ``g_e - L_e``. The class's first
    contact is never above ``g_e' + B_e'`` for any of its pairs (``B`` the same
    bound with the pair's own ``|nt|`` times ``_REFINED_NT``): a pair with
    ``g_e - L_e`` above the smallest of those is never first.
    """
    if not pending:
        return np.zeros(0, dtype=bool)
    g = np.concatenate([sv.rows["g"] for sv in pending])
    m = np.concatenate([sv.rows["m"] for sv in pending])
    c = np.concatenate([sv.rows["c"] for sv in pending])
    ntn = np.concatenate([np.hypot(*sv.rows["nt"].T) for sv in pending])
    # a second feature's contact point is on the tooth moved radially by up to the reach
    arm = float(np.hypot(*flex.local.T).max()) + imp.flex_ecc + imp.rigid_ecc + imp.cam_flex + imp.cam_fixed
    speed = np.concatenate([np.hypot(*sv.poses.dshift[sv.k].T) + np.abs(sv.poses.drot[sv.k]) * arm for sv in pending])
    q_max = float(np.hypot(*rigid.local.T).max())
    A_b = 0.5 * imp.rigid_runout / tab.r_b
    A_a = (0.5 * imp.flex_runout + imp.flex_ecc) / tab.r_g
    reach = imp.rigid_ecc + c * (imp.cam_flex + imp.cam_fixed) + A_b * q_max + A_a * speed + imp.flex_ecc
    L = np.maximum(_REFINED_NT * ntn, NT_MAX / tab.r_b) * reach
    B = _REFINED_NT * ntn * reach
    cls = m % tab.N
    top = np.full(tab.N, np.inf)
    np.minimum.at(top, cls, g + B)
    return g - L <= top[cls] + 1e-12


#: radial moves of a flexspline tooth, in units of the errors' radial reach, at which each pair is solved
#: again for the feature it touches there
_RADIAL_STEPS = (-0.25, 0.25, -0.5, 0.5, -1.0, 1.0)
#: a contact found with the tooth moved is another feature when it closes earlier than the lines known
#: predict by more than this, rad (0.01 arcsec)
_LINE_TOL = 0.01 / ARCSEC_PER_RAD


def _second_features(lat: _Lattice, sv: _Solved, sub, side: int, rho: float, warm: bool = True):
    """Contacts on the features pairs ``sub`` of ``sv`` touch once the errors move their flexspline teeth radially by
    up to ``rho``.

    Where the tooth space is locally convex (a tip running from the other's
    flank into its root fillet), the closing rotation is the smaller of the
    two features' and each is linear in the errors: the second feature's
    closing rotation, carried back to the perfect pose along its own
    sensitivity, is one more candidate of the lattice class, and the KE's
    minimum over candidates picks it where it is first. Kept only where it is
    no earlier than the perfect contact at the perfect pose (a lower envelope;
    where a corner turns the other way the smaller rotation would be wrong).
    """
    out = []
    rows = {key: v[sub] for key, v in sv.rows.items()}
    k, P = sv.k[sub], sv.poses
    r_b = lat.drive.rigid.r

    def solve(f, kk):
        pk = P.take(k[kk])
        ii = pk.idx
        sh = P.shift[ii] + f * rho * np.stack([np.cos(P.rot[ii]), np.sin(P.rot[ii])], -1)
        # started 1 um of gap before where the pair's own line puts the moved contact (as _refine): a Newton
        # step or two when the feature stays, a bracket and a few steps when it changes
        start = rows["g"][kk] - f * rho * rows["a_rho"][kk] - _FD_START * np.hypot(*rows["nt"][kk].T) if warm else None
        with np.errstate(invalid="ignore"):
            c2 = closing_rotation(
                lat.flex, P.rot[ii], sh, lat.rigid, sv.rb[k[kk]], np.zeros((len(kk), 2)), side, lat.reach, start=start
            )
            c2.delta = np.where(c2.ok, c2.delta, 0.0)
            r2 = _rows(c2, np.arange(len(kk)), pk, side, np.ones(len(kk)))
        return c2, r2

    # the full reach first, every pair: those whose closing rotation there is off the perfect contact's
    # line (either way) or not found are the ones whose feature changes within the reach
    full = {}
    for f in (-1.0, 1.0):
        c2, r2 = solve(f, np.arange(len(k)))
        pred = rows["g"] - f * rho * rows["a_rho"]
        moved = ~c2.ok | (np.abs(c2.delta - pred) > _LINE_TOL)
        full[f] = (c2, r2, np.nonzero(moved)[0])
    kk = np.unique(np.concatenate([full[-1.0][2], full[1.0][2]]))
    if kk.size == 0:
        return out
    # the lines known per moved pair (the perfect contact's, then those added): closing rotation at the
    # perfect pose and a_rho, NaN where a pair has fewer
    lines = [(rows["g"][kk], rows["a_rho"][kk])]
    for f in _RADIAL_STEPS:  # closest first: a line found there is not added again further out
        if abs(f) == 1.0:
            c2, r2, _ = full[f]
            c2 = type(c2)(c2.delta[kk], c2.p[kk], c2.q[kk], c2.nt[kk], c2.ok[kk])
            r2 = {key: v[kk] for key, v in r2.items()}
        else:
            c2, r2 = solve(f, kk)
        dr = f * rho
        # back to the perfect pose: the radial move changed the closing rotation by -dr a_rho
        g0 = c2.delta + dr * r2["a_rho"]
        # below every line known: another feature is first here
        off = c2.ok.copy()
        for g_l, a_l in lines:
            off &= ~(c2.delta >= g_l - dr * a_l - _LINE_TOL)  # a NaN line (none) does not hold it back
        new = (
            off
            & np.all(np.isfinite(c2.nt), axis=1)
            & (np.hypot(*c2.nt.T) * r_b <= NT_MAX)
            & (g0 >= rows["g"][kk] - 1e-12)
        )
        sel = np.nonzero(new)[0]
        lines.append((np.where(new, g0, np.nan), np.where(new, r2["a_rho"], np.nan)))
        if sel.size:
            r2 = {key: v[sel] for key, v in r2.items()}
            r2["g"] = g0[sel]
            out.append(r2)
    return out


#: gap (mm) before the unperturbed contact where the finite-difference solves start (0: from rest)
_FD_START = 1e-3
#: translation (mm) of the rigid tooth for the finite-difference sensitivities: 0.1 um, where the
#: closing rotation (converged to a 1e-8 mm gap) is known to 1e-4 of the difference
_FD_H = 1e-4


def _refine(tab: ContactTable, side: int, imp: Imperfections, flex, rigid, reach: float) -> None:
    """Sensitivities of the contacts that can be first to touch, by central differences.

    The nearest-point normal is exact on a flank, but where a tooth's corner
    meets the other outline's vertex (tip corners, interfering teeth) it is
    not the direction the contact slides in; translating the rigid tooth by
    +-0.1 um in x and y and solving again gives the true ``nt``.
    """
    S = tab.sides[side]
    lanes = candidate_lanes(tab, side, imp, slack=2.0)
    e = np.unique(lanes[lanes >= 0])
    e = e[S["extra"][e] == 0]  # a second feature's solve from the perfect pose would find the first
    if e.size == 0:
        return
    rb = (S["j"][e] + 0.5) * 2 * pi / tab.z_b
    nt = np.empty((e.size, 2))
    # started 1 um of gap before the unperturbed contact (apart, ten times the perturbation): a Newton
    # step or two to the perturbed one instead of five or six from rest
    start = S["g"][e] - _FD_START * np.hypot(S["nt"][e, 0], S["nt"][e, 1]) if _FD_START else None
    for ax in (0, 1):
        dv = np.zeros((e.size, 2))
        dv[:, ax] = _FD_H
        # only the rotations are differenced: no nearest points read at the contacts (one measurement less)
        cp = closing_rotation(
            flex, S["rot"][e], S["shift"][e], rigid, rb, dv, side, reach, start=start, contact_data=False
        )
        cm = closing_rotation(
            flex, S["rot"][e], S["shift"][e], rigid, rb, -dv, side, reach, start=start, contact_data=False
        )
        nt[:, ax] = (cp.delta - cm.delta) / (2 * _FD_H)
    # a difference across a switch of the touching feature is no derivative: keep the nearest-point
    # normal's value there (within 50 % of it is a slide along one feature; the corner cases differ by ~10 %)
    good = np.all(np.isfinite(nt), axis=1) & (np.hypot(*(nt - S["nt"][e]).T) <= 0.5 * np.hypot(*S["nt"][e].T))
    e, nt = e[good], nt[good]
    S["nt"][e] = nt
    S["a_phi"][e] = np.einsum("ij,ij->i", S["dP"][e], nt)
    S["a_rho"][e] = np.cos(S["rr"][e]) * nt[:, 0] + np.sin(S["rr"][e]) * nt[:, 1]
    S["a_beta"][e] = -S["q"][e, 1] * nt[:, 0] + S["q"][e, 0] * nt[:, 1]
    for key in ("_lane_factors", "_harmonic_factors"):  # of the sensitivities before
        tab.__dict__.pop(key, None)
