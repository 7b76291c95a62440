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
from .distance import Template, signed_clearance

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
    c, s = np.cos(t), np.sin(t)
    return rot + t, np.stack([c * shift[:, 0] - s * shift[:, 1], s * shift[:, 0] + c * shift[:, 1]], axis=-1)


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
    rot = np.asarray(rot, dtype=float)
    K = len(rot)
    shift = np.asarray(shift, dtype=float).reshape(K, 2)
    rot_b = np.broadcast_to(np.asarray(rot_b, dtype=float), (K,))
    shift_b = np.asarray(shift_b, dtype=float).reshape(K, 2)
    rigid_g = shapely.polygons(transform(rigid.local, rot_b, shift_b))
    lever = float(np.hypot(shift[:, 0], shift[:, 1]).max() + np.hypot(*flex.local.T).max()) if K else 1.0

    def measure(t, idx):
        """Signed gap at rotation t of pairs idx, and nearest points where apart."""
        r, sh = _turn(rot[idx], shift[idx], side * t)
        geo = shapely.polygons(transform(flex.local, r, sh))
        line = shapely.get_coordinates(shapely.shortest_line(geo, rigid_g[idx])).reshape(-1, 2, 2)
        d = np.hypot(*(line[:, 1] - line[:, 0]).T)
        over = np.nonzero(d == 0.0)[0]
        if over.size:
            d[over] = signed_clearance(
                flex,
                r[over],
                sh[over],
                rigid,
                rot_b[idx][over],
                shift_b[idx][over],
                b_geoms=rigid_g[idx][over],
                a_geoms=geo[over],
            )
            d[over] = np.minimum(d[over], -1e-15)
        return d, line

    t = np.zeros(K) if start is None else np.array(np.broadcast_to(np.asarray(start, dtype=float), (K,)))
    lo_t = np.full(K, -np.inf)  # largest rotation known apart, and its gap
    lo_d = np.full(K, np.nan)
    hi_t = np.full(K, np.inf)  # smallest rotation known overlapping, and its (negative) gap
    hi_d = np.full(K, np.nan)
    last = np.zeros(K, dtype=int)  # side of the previous bracket update (Illinois)
    ok = np.ones(K, dtype=bool)
    done = np.zeros(K, dtype=bool)
    p = np.full((K, 2), np.nan)
    q = np.full((K, 2), np.nan)
    nt = np.full((K, 2), np.nan)
    active = np.arange(K)
    for _ in range(MAX_ITER):
        if active.size == 0:
            break
        d, line = measure(t[active], active)
        apart = d > 0.0
        # overlapping: new upper end of the bracket
        ia = active[~apart]
        if ia.size:
            hi_t[ia], hi_d[ia] = t[ia], d[~apart]
            lo_d[ia[last[ia] == -1]] *= 0.5
            last[ia] = -1
        ib = active[apart]
        rate = np.zeros(0)
        if ib.size:
            dd = d[apart]
            pp, qq = line[apart, 0], line[apart, 1]
            n = (qq - pp) / dd[:, None]
            rate = side * (-pp[:, 1] * n[:, 0] + pp[:, 0] * n[:, 1])  # s (z x p) . n
            lo_t[ib], lo_d[ib] = t[ib], dd
            hi_d[ib[last[ib] == 1]] *= 0.5
            last[ib] = 1
            p[ib], q[ib] = pp, qq
            with np.errstate(divide="ignore", invalid="ignore"):
                nt[ib] = n / rate[:, None]
            fin = dd < GAP_TOL
            done[ib[fin]] = True
            stuck = (rate <= 1e-6 * lever) & ~fin & ~np.isfinite(hi_t[ib])
            ok[ib[stuck]] = False
            done[ib[stuck]] = True
            step_n = np.where(rate > 1e-6 * lever, dd / np.maximum(rate, 1e-300), np.inf)
        # next rotation of every pair still going
        nxt = t.copy()
        if ib.size:
            nxt[ib] = t[ib] + step_n
        if ia.size:
            no_lo = ~np.isfinite(lo_t[ia])
            # overlapping from the start: turn back by twice the depth over the lever arm
            nxt[ia[no_lo]] = t[ia[no_lo]] + 4.0 * hi_d[ia[no_lo]] / lever - 1e-7
        br = np.isfinite(lo_t) & np.isfinite(hi_t)
        rf = lo_t + lo_d * (hi_t - lo_t) / (lo_d - hi_d)
        use_rf = br & ((nxt >= hi_t) | (nxt <= lo_t) | (last == -1))
        nxt = np.where(use_rf, rf, nxt)
        tight = br & ((hi_t - lo_t) * lever < 0.1 * GAP_TOL)
        done |= tight & np.isfinite(lo_d)
        far = np.abs(nxt) > reach  # beyond reach either way (turned back past a neighbour: a jam)
        ok[far & ~done] = False
        done |= far
        t = np.where(done, t, nxt)
        active = np.nonzero(~done)[0]
    ok[active] = False  # not converged
    delta = np.where(ok, lo_t, np.inf)
    # The contact's data from the nearest points at a fixed small gap, BACKOFF, rather than at the
    # iterate the search happened to end on: where a corner meets the other outline (or a vertex a
    # vertex) the nearest-point direction at a vanishing gap depends on the path the search took
    # (two searches of one contact from different starts gave normals up to 90 % apart; on D2 [S4]
    # 11 % of the KE samples were up to 35 arcsec off the direct computation);
    # at a fixed gap just before touching it is the direction the contact closes along.
    back = np.nonzero(ok & np.all(np.isfinite(nt), axis=1))[0]
    if back.size and contact_data:
        tb = delta[back] - BACKOFF * np.hypot(nt[back, 0], nt[back, 1])
        d, line = measure(tb, back)
        good = d > 0.25 * BACKOFF
        b = back[good]
        pp, qq, dd = line[good, 0], line[good, 1], d[good]
        n = (qq - pp) / dd[:, None]
        rate = side * (-pp[:, 1] * n[:, 0] + pp[:, 0] * n[:, 1])
        fine = rate > 1e-6 * lever
        b, pp, qq, n, rate = b[fine], pp[fine], qq[fine], n[fine], rate[fine]
        p[b], q[b], nt[b] = pp, qq, n / rate[:, None]
    return Contact(delta, p, q, nt, ok)


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
