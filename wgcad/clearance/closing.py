"""Flank contact by rotation: the flexspline rotation that closes a tooth's gap, and its sensitivity to small tooth motions (docs/models.md 6.2).

A flexspline tooth at pose ``(rot, shift)`` and a rigid tooth: turning the
flexspline about the drive axis by ``s * delta`` (``s = +1``: counter-clockwise,
towards the rigid tooth above it) closes their gap at ``delta``. At contact,
with ``p`` and ``q`` the nearest points of the two outlines just before they
touch and ``n`` the unit vector from ``p`` to ``q``, a small motion ``u_f`` of
the flexspline tooth at ``p`` and ``u_b`` of the rigid tooth at ``q`` change
the closing rotation by

    d delta = (u_b - u_f) . n / (s (z x p) . n)  =  (u_b - u_f) . nt

to first order (the gap ``(q - p) . n`` changes by ``(u_b - u_f) . n``, and a
rotation ``s delta`` moves ``p`` by ``s delta z x p``). ``nt`` is stored per
contact; it is what lets the KE of an imperfect drive reuse the perfect
drive's contacts (:mod:`wgcad.accuracy.ke`). :func:`closing_direct` is
the same from the exact poses of every tooth of an imperfect drive: the
KE's reference and the imperfect audit's backlash.
"""

from __future__ import annotations

from math import pi

import numpy as np
import shapely

from ..errors import DesignError
from ..placement import transform
from ..placement.imperfect import Imperfections, flex_poses, rigid_poses
from ..plane import rotate
from .distance import Template, overlap_depth
from .threads import in_halves

__all__ = ["Contact", "closing_rotation", "closing_direct"]

#: gap (mm) at which Newton's iteration stops: 1e-8 mm is 1e-10 rad of output
#: rotation at 80 mm, 2e-5 arcsec, far below any KE figure
GAP_TOL = 1e-8
#: gap (mm) at which a contact's nearest points and normal are read, just before touching: 10 nm,
#: 1000 times the convergence gap (so rounding cannot turn the direction) and far below any feature
BACKOFF = 1e-5
#: iterations of Newton's method (with bisection on overshoot); a contact
#: converges in 3-6, so one that needs more is a grazing contact at the edge of
#: the mesh and is dropped as "no contact within reach"
MAX_ITER = 40


class Contact:
    """Closing rotations and contact data of K tooth pairs (arrays, NaN/inf where no contact is reachable).

    Attributes
    ----------
    delta : (K,) float
        Rotation (rad) in direction ``side`` that makes the pair touch;
        negative when the pair overlaps (the rotation that separates it).
    p, q : (K, 2) float
        Nearest points of the flexspline and the rigid outline at contact.
    nt : (K, 2) float
        ``n / (s (z x p) . n)``, mm^-1: the closing rotation's sensitivity
        to a relative motion ``u_b - u_f`` of the teeth at the contact.
    ok : (K,) bool
        Contact found within reach.
    """

    def __init__(self, delta, p, q, nt, ok):
        self.delta, self.p, self.q, self.nt, self.ok = delta, p, q, nt, ok


def _turn(rot, shift, t):
    return rot + t, rotate(shift, t)


def _nearest_part(local, r, sh, rigid_g):
    geo = shapely.polygons(transform(local, r, sh))
    return shapely.get_coordinates(shapely.shortest_line(geo, rigid_g)).reshape(-1, 2, 2)


def _nearest(local, r, sh, rigid_g):
    """The nearest points ``(K, 2, 2)`` (flexspline point first) of the flexspline outline ``local`` placed at
    ``(r, sh)`` (K poses) to the rigid teeth ``rigid_g``, on two threads for many pairs (shapely releases the GIL in
    its queries, so the two halves run at once)."""
    return in_halves(_nearest_part, (r, sh, rigid_g), shared=(local,))


class _Pairs:
    """K tooth pairs: the rigid teeth fixed, the flexspline teeth turned about the axis in direction ``side``."""

    def __init__(self, flex: Template, rot, shift, rigid: Template, rot_b, shift_b, side: float):
        self.flex, self.rigid, self.side = flex, rigid, side
        self.rot = np.asarray(rot, dtype=float)
        K = len(self.rot)
        self.shift = np.asarray(shift, dtype=float).reshape(K, 2)
        self.rot_b = np.broadcast_to(np.asarray(rot_b, dtype=float), (K,))
        self.shift_b = np.asarray(shift_b, dtype=float).reshape(K, 2)
        # the rigid teeth: a few hundred distinct poses among thousands of pairs, each built once (the geometries are
        # immutable and shared by the pairs that face the same tooth)
        poses, inv = np.unique(np.column_stack([self.rot_b, self.shift_b]), axis=0, return_inverse=True)
        self.rigid_g = shapely.polygons(transform(rigid.local, poses[:, 0], poses[:, 1:]))[inv.ravel()]
        #: the largest distance of a flexspline outline point from the axis, mm
        self.lever = (
            float(np.hypot(self.shift[:, 0], self.shift[:, 1]).max() + np.hypot(*flex.local.T).max()) if K else 1.0
        )

    def measure(self, t, idx):
        """Signed gap at rotation t of pairs idx, and nearest points where apart."""
        r, sh = _turn(self.rot[idx], self.shift[idx], self.side * t)
        line = _nearest(self.flex.local, r, sh, self.rigid_g[idx])
        d = np.hypot(*(line[:, 1] - line[:, 0]).T)
        over = np.nonzero(d == 0.0)[0]
        if over.size:
            # the boundaries touch or cross (shortest_line is GEOS's distance): only the depth is left to measure
            d[over] = -overlap_depth(
                self.flex, r[over], sh[over], self.rigid, self.rot_b[idx][over], self.shift_b[idx][over]
            )
            d[over] = np.minimum(d[over], -1e-15)
        return d, line

    def closing_rate(self, pp, qq, dd):
        """Unit normals ``n`` from ``pp`` to ``qq`` (gap ``dd``) and the rate ``s (z x p) . n`` the gap falls at."""
        n = (qq - pp) / dd[:, None]
        return n, self.side * (-pp[:, 1] * n[:, 0] + pp[:, 0] * n[:, 1])


class _Bracket:
    """The safeguarded Newton search's state per pair: the largest rotation known apart and the smallest known
    overlapping (with their gaps), the side of the last update (Illinois), the contact data of the last apart
    iterate, and whether a pair is done and found."""

    def __init__(self, K: int):
        self.lo_t = np.full(K, -np.inf)
        self.lo_d = np.full(K, np.nan)
        self.hi_t = np.full(K, np.inf)
        self.hi_d = np.full(K, np.nan)
        self.last = np.zeros(K, dtype=int)
        self.ok = np.ones(K, dtype=bool)
        self.done = np.zeros(K, dtype=bool)
        self.p = np.full((K, 2), np.nan)
        self.q = np.full((K, 2), np.nan)
        self.nt = np.full((K, 2), np.nan)

    def overlapping(self, ia, t, d):
        """Pairs ``ia`` overlap at ``t``: a new upper end of their bracket."""
        self.hi_t[ia], self.hi_d[ia] = t[ia], d
        self.lo_d[ia[self.last[ia] == -1]] *= 0.5
        self.last[ia] = -1

    def apart(self, ib, t, d, line, pairs: _Pairs):
        """Pairs ``ib`` apart at ``t`` with gaps ``d``: a new lower end, their contact data; the Newton steps."""
        pp, qq = line[:, 0], line[:, 1]
        n, rate = pairs.closing_rate(pp, qq, d)
        self.lo_t[ib], self.lo_d[ib] = t[ib], d
        self.hi_d[ib[self.last[ib] == 1]] *= 0.5
        self.last[ib] = 1
        self.p[ib], self.q[ib] = pp, qq
        with np.errstate(divide="ignore", invalid="ignore"):
            self.nt[ib] = n / rate[:, None]
        fin = d < GAP_TOL
        self.done[ib[fin]] = True
        stuck = (rate <= 1e-6 * pairs.lever) & ~fin & ~np.isfinite(self.hi_t[ib])
        self.ok[ib[stuck]] = False
        self.done[ib[stuck]] = True
        return np.where(rate > 1e-6 * pairs.lever, d / np.maximum(rate, 1e-300), np.inf)

    def next_rotation(self, t, ia, ib, step_n, lever: float, reach: float):
        """The next rotation of every pair still going (regula falsi where Newton leaves the bracket)."""
        nxt = t.copy()
        if ib.size:
            nxt[ib] = t[ib] + step_n
        if ia.size:
            no_lo = ~np.isfinite(self.lo_t[ia])
            # overlapping from the start: turn back by twice the depth over the lever arm
            nxt[ia[no_lo]] = t[ia[no_lo]] + 4.0 * self.hi_d[ia[no_lo]] / lever - 1e-7
        lo_t, hi_t = self.lo_t, self.hi_t
        br = np.isfinite(lo_t) & np.isfinite(hi_t)
        rf = lo_t + self.lo_d * (hi_t - lo_t) / (self.lo_d - self.hi_d)
        use_rf = br & ((nxt >= hi_t) | (nxt <= lo_t) | (self.last == -1))
        nxt = np.where(use_rf, rf, nxt)
        tight = br & ((hi_t - lo_t) * lever < 0.1 * GAP_TOL)
        self.done |= tight & np.isfinite(self.lo_d)
        far = np.abs(nxt) > reach  # beyond reach either way (turned back past a neighbour: a jam)
        self.ok[far & ~self.done] = False
        self.done |= far
        return np.where(self.done, t, nxt)


def _backed_off_contacts(pairs: _Pairs, br: _Bracket, delta) -> None:
    """Read each found contact's nearest points and ``nt`` at the gap BACKOFF before it touches.

    Rather than at the iterate the search happened to end on: where a corner meets the other outline (or a
    vertex a vertex) the nearest-point direction at a vanishing gap depends on the path the search took (two
    searches of one contact from different starts gave normals up to 90 % apart; on D2 [S4] 11 % of the KE
    samples were up to 35 arcsec off the direct computation); at a fixed gap just before touching it is the
    direction the contact closes along."""
    back = np.nonzero(br.ok & np.all(np.isfinite(br.nt), axis=1))[0]
    if not back.size:
        return
    tb = delta[back] - BACKOFF * np.hypot(br.nt[back, 0], br.nt[back, 1])
    d, line = pairs.measure(tb, back)
    good = d > 0.25 * BACKOFF
    b = back[good]
    pp, qq, dd = line[good, 0], line[good, 1], d[good]
    n, rate = pairs.closing_rate(pp, qq, dd)
    fine = rate > 1e-6 * pairs.lever
    b, pp, qq, n, rate = b[fine], pp[fine], qq[fine], n[fine], rate[fine]
    br.p[b], br.q[b], br.nt[b] = pp, qq, n / rate[:, None]


def closing_rotation(
    flex: Template,
    rot,
    shift,
    rigid: Template,
    rot_b,
    shift_b,
    side: float,
    reach: float,
    start=None,
    contact_data: bool = True,
) -> Contact:
    """Rotation of the flexspline (about the axis, direction ``side``) that brings each tooth into contact with its rigid tooth.

    Newton's method on the gap (it falls at ``s (z x p) . n`` per radian),
    safeguarded by a bracket: a step into overlap is replaced by a
    regula-falsi step (Illinois variant) between the last separated rotation
    and the overlapping one, whose signed clearance is minus the penetration
    depth (:func:`wgcad.clearance.distance.signed_clearance`). Pairs that
    overlap at the start are first turned back until they separate.

    Parameters
    ----------
    flex, rigid : Template
        Tooth outlines in their tooth frames.
    rot, shift, rot_b, shift_b : (K,), (K, 2)
        Poses of the flexspline teeth and of the rigid teeth they face.
    side : {+1, -1}
        Direction of rotation (+1 counter-clockwise).
    reach : float
        Largest rotation looked at, rad; pairs that need more get ``inf``.
    start : (K,) float, optional
        Rotations (rad, direction ``side``) to start from instead of 0. Only
        a start where the pair is still apart (before its contact) is safe:
        from an overlapping start the search turns back and can end at
        another contact.
    contact_data : bool
        Read the nearest points and ``nt`` at a fixed small gap before the
        contact (one more measurement of every pair); without it ``p``,
        ``q``, ``nt`` are those of the last iterate, for callers that use
        only ``delta`` (the finite differences of the KE table).

    Returns
    -------
    Contact
    """
    pairs = _Pairs(flex, rot, shift, rigid, rot_b, shift_b, side)
    K = len(pairs.rot)
    t = np.zeros(K) if start is None else np.array(np.broadcast_to(np.asarray(start, dtype=float), (K,)))
    br = _Bracket(K)
    active = np.arange(K)
    for _ in range(MAX_ITER):
        if active.size == 0:
            break
        d, line = pairs.measure(t[active], active)
        apart = d > 0.0
        ia, ib = active[~apart], active[apart]
        if ia.size:
            br.overlapping(ia, t, d[~apart])
        step_n = br.apart(ib, t, d[apart], line[apart], pairs) if ib.size else None
        t = br.next_rotation(t, ia, ib, step_n, pairs.lever, reach)
        active = np.nonzero(~br.done)[0]
    br.ok[active] = False  # not converged
    delta = np.where(br.ok, br.lo_t, np.inf)
    if contact_data:
        _backed_off_contacts(pairs, br, delta)
    return Contact(delta, br.p, br.q, br.nt, br.ok)


def closing_direct(drive, imp: Imperfections, phi_h: float, side: int, sections=None) -> float:
    """The closing rotation at ``phi_h`` from the exact poses of every tooth (no table, no linearisation), rad.

    The first of the radially engaged teeth to touch when the flexspline
    turns towards ``side`` (rigid gear fixed), over ``sections`` (default:
    the audit's three on a coned flexspline).
    """
    d = drive.design.drive
    if d.fixed != "rigid":
        raise DesignError(
            "drive.fixed", f"the imperfect poses take the rigid gear as fixed (docs/models.md 6.2); got '{d.fixed}'"
        )
    z_b = d.z_rigid
    if sections is None:
        sections = [float(z) for z in drive.sections(3)] if drive.coned else [None]
    flex, rigid = Template(drive.flex.tooth_polygon()), Template(drive.rigid.tooth_polygon())
    rr, rs = rigid_poses(drive, imp)
    best = np.inf
    gamma_b = 2 * pi / z_b
    for z in sections:
        rot, shift = flex_poses(drive, imp, phi_h, z=z)
        a = np.arctan2(shift[:, 1] + drive.r_m * np.sin(rot), shift[:, 0] + drive.r_m * np.cos(rot))
        pts_r = np.hypot(*transform(flex.local, rot, shift).transpose(2, 0, 1))
        # radially engaged: the tooth reaches past the rigid tip circle (docs/models.md 7, culling)
        near = (pts_r.min(axis=1) <= drive.rigid.r_a) if drive.external else (pts_r.max(axis=1) >= drive.rigid.r_a)
        idx = np.nonzero(near)[0]
        lo = np.floor(a[idx] / gamma_b - 0.5).astype(int)
        j = (lo + (1 if side > 0 else 0)) % z_b
        con = closing_rotation(flex, rot[idx], shift[idx], rigid, rr[j], rs[j], side, 0.5 * 2 * pi / d.z_flex)
        if con.ok.any():
            best = min(best, float(con.delta[con.ok].min()))
    return best
