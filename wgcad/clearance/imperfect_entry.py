"""Entry gap and pinch of an imperfect drive: every passage of a tooth through the entry, each with its own crossing (docs/models.md 5, 6.2).

With errors no passage stands for the others: tooth ``k`` enters zone ``w``
in generator turn ``n`` with its own run-out, eccentricity and cam offset
against the rigid teeth it meets there. Each passage through the swept
generator angles is found from the perfect drive's crossing (its tooth at
the perfect crossing's tooth angle), then

* **the crossing**: the generator angle where the passage's tip arc meets
  the rigid tip circle (the exact radial gap of :meth:`Scene.tip_radial`, on
  the imperfect poses, in the rigid gear's own frame), bracketed on a grid
  of tooth-angle offsets around the perfect crossing and closed by regula
  falsi; the entry gap is the clearance there, the smallest over passages
  and sections, refined on the exact curves;
* **the pinch**: each passage's clearance over a window around the perfect
  pinch, moved by the passage's own crossing shift; the passages whose
  window can hold the smallest value are searched within the window
  (:func:`wgcad.clearance.entry.lipschitz_min`) and the best refined on the
  exact curves by nested grids, as for the perfect drive.
"""

from __future__ import annotations

from math import pi

import numpy as np

from ..drive import build_drive
from ..placement.imperfect import flex_poses_batch
from .entry import PINCH_STEP, lipschitz_min
from .imperfect_scene import ImperfectScene
from .scene import Scene, clearance_at_poses, refine_min

__all__ = ["passages", "imperfect_entry", "CROSS_WINDOW"]

#: tooth-angle window (rad) either side of the perfect crossing in which a passage's crossing is looked for:
#: 8 deg. A radial error moves the crossing by (error) / (dw/dphi); at D1's crossing (70 deg) dw/dphi is
#: ~1.4 mm/rad, so 0.1 mm of error moves it ~4 deg
CROSS_WINDOW = np.deg2rad(8.0)
_CROSS_GRID = 33  # 0.5 deg steps over the window (then regula falsi in the bracket)
_FALSI = 40  # regula falsi steps (Illinois): to 1e-12 rad of tooth angle or the iteration limit
#: passages handled at once: their crossing grids (65 poses each) and pinch windows stay a few MB whatever the
#: number of turns swept (the whole 100-turn cycle of D1 has 121,200 passages)
_CHUNK = 1024
#: pinch windows searched at once (lowest bounds first)
_PINCH_BATCH = 64
#: passages refined on the exact curves at once (lowest polygon figures first)
_REFINE_BATCH = 16
#: more candidates than this are first sorted out on polygons 8 times finer (as wgcad.clearance.imperfect)
_FINE_ABOVE = 48
#: half-width (rad) of the window around a passage's moved perfect pinch: two pinch grid steps
PINCH_HALF = 2.0 * PINCH_STEP


def passages(scene, p_star: float, phi_lo: float, phi_hi: float):
    """Every passage of a tooth through tooth angle ``p_star`` (+ a multiple of ``2 pi / n_w``) at generator angles in ``[phi_lo, phi_hi)``.

    A tooth's angle from the major axis is ``2 pi k / z_g + c phi_h`` with
    ``c = 1 / u_hg - 1`` (the flexspline turning against the cam).

    Returns
    -------
    phi_h : (P,) float
        The perfect drive's generator angle of the passage, rad.
    k : (P,) int
        The tooth.
    """
    z_g, n_w = scene.z_g, scene.n_w
    c = 1.0 / scene.ratios["u_hg"] - 1.0
    k = np.arange(z_g)
    base = p_star - 2.0 * pi * k / z_g
    # phi_h = (base + 2 pi j / n_w) / c for whole j: the j that land in the range
    ends = np.stack([(c * phi_lo - base), (c * phi_hi - base)]) * n_w / (2.0 * pi)
    j0 = np.floor(ends.min(axis=0)).astype(int) - 1
    j1 = np.ceil(ends.max(axis=0)).astype(int) + 1
    kk = np.repeat(k, j1 - j0 + 1)
    jj = np.concatenate([np.arange(a, b + 1) for a, b in zip(j0, j1)])
    ph = (base[kk] + 2.0 * pi * jj / n_w) / c
    keep = (ph >= phi_lo) & (ph < phi_hi)
    o = np.argsort(ph[keep], kind="stable")
    return ph[keep][o], kk[keep][o]


def _poses(drive, imp, isc, phi_h, k, z):
    rot, shift = flex_poses_batch(drive, imp, phi_h, k, [z])[0]
    return rot, isc.relative(shift)


def _crossings(drive, imp, isc, phi0, k, z, sgn):
    """Generator angle of each passage's entry crossing (NaN where none in the window), section ``z``."""
    c = 1.0 / isc.ratios["u_hg"] - 1.0
    # offsets of the tooth angle from the perfect crossing, away from the major axis last (the tip leaves
    # the rigid tip circle going away from the axis: overlap f <= 0 before, clear f > 0 after)
    d = sgn * np.linspace(-CROSS_WINDOW, CROSS_WINDOW, _CROSS_GRID)
    P, G = len(phi0), len(d)
    ph = phi0[:, None] + d[None, :] / c
    f = isc.tip_radial(*_poses(drive, imp, isc, ph.ravel(), np.repeat(k, G), z)).reshape(P, G)
    up = (f[:, :-1] <= 0.0) & (f[:, 1:] > 0.0)
    # the crossing nearest the perfect one (the window's middle)
    mid = (G - 1) / 2.0
    score = np.where(up, np.abs(np.arange(G - 1) + 0.5 - mid), np.inf)
    i = np.argmin(score, axis=1)
    ok = np.isfinite(score[np.arange(P), i])
    out = np.full(P, np.nan)
    if not ok.any():
        return out
    r = np.nonzero(ok)[0]
    a, b = ph[r, i[r]], ph[r, i[r] + 1]
    fa, fb = f[r, i[r]], f[r, i[r] + 1]
    for _ in range(_FALSI):
        x = a - fa * (b - a) / (fb - fa)
        fx = isc.tip_radial(*_poses(drive, imp, isc, x, k[r], z))
        left = fx <= 0.0
        # Illinois: halve the stale end's value
        fb = np.where(left, fb * 0.5, fx)
        b = np.where(left, b, x)
        fa = np.where(left, fx, fa * 0.5)
        a = np.where(left, x, a)
        if np.all(np.abs(b - a) * abs(c) < 1e-12):
            break
    out[r] = np.where(np.abs(fa) <= np.abs(fb), a, b)
    return out


def imperfect_entry(drive, imp, isc, scene, perfect_gaps, perfect_pinch, angles, sections, refine: bool):
    """Entry gap and pinch over every passage in the swept generator angles (module docstring).

    Parameters
    ----------
    isc, scene : ImperfectScene, Scene
        The imperfect drive and its perfect twin.
    perfect_gaps : list of ((gap, phi), z)
        :func:`wgcad.clearance.entry.entry_crossings` of the perfect drive with its sections.
    perfect_pinch : tuple or None
        :func:`wgcad.clearance.entry.entry_pinch` of the perfect drive.

    Returns
    -------
    dict with ``gap``, ``gap_phi_h``, ``gap_tooth``, ``gap_z``, ``gap_tooth_angle`` and, where the perfect drive
    has a pinch, ``pinch``, ``pinch_phi_h``, ``pinch_tooth``, ``pinch_z``, ``pinch_tooth_angle``,
    ``pinch_rigid``; ``passages`` (per section), ``spread`` (largest minus smallest passage gap), mm and rad;
    ``all``: every passage's generator angle, gap on the polygons and section index.
    """
    sgn = scene.entry_sign
    step = float(np.median(np.diff(angles))) if len(angles) > 1 else 2.0 * pi
    lo, hi = float(angles[0]), float(angles[-1]) + step
    c = 1.0 / scene.ratios["u_hg"] - 1.0
    out = {"gap": np.nan, "pinch": np.nan, "passages": 0}
    rows = []  # (value, phi_h, k, si) of every passage's crossing
    shifts = {}
    for si, ((g0, p0), z) in enumerate(perfect_gaps):
        if not np.isfinite(g0):
            continue
        ph0, k = passages(scene, p0, lo, hi)
        ph = np.concatenate(
            [
                _crossings(drive, imp, isc, ph0[a : a + _CHUNK], k[a : a + _CHUNK], z, sgn)
                for a in range(0, len(ph0), _CHUNK)
            ]
            or [np.zeros(0)]
        )
        ok = np.isfinite(ph)
        po, ko = ph[ok], k[ok]
        v = np.concatenate(
            [
                clearance_at_poses(isc, *_poses(drive, imp, isc, po[a : a + _CHUNK], ko[a : a + _CHUNK], z)).min
                for a in range(0, len(po), _CHUNK)
            ]
            or [np.zeros(0)]
        )
        rows.append((v, ph[ok], k[ok], np.full(int(ok.sum()), si)))
        shifts[si] = (ph0, k, ph - ph0)  # the crossing's shift in generator angle, NaN where none
        out["passages"] += int(len(ph0))
    if not rows or not sum(len(r[0]) for r in rows):
        return out
    v, ph, k, si = (np.concatenate(x) for x in zip(*rows))
    out["spread"] = float(v.max() - v.min())
    out["all"] = {"phi_h": ph, "gap": v, "section": si}  # every passage's polygon figure (for the picture)
    best = int(np.argmin(v))
    if refine:
        # a passage's exact gap is within the polygons' chord_gap of its polygon one: refined lowest first, in
        # batches, until the next polygon figure less that margin is above the best exact one
        order = np.argsort(v, kind="stable")
        order = order[v[order] - isc.chord_gap <= v[order[0]] + isc.chord_gap]  # those that can hold the minimum
        vr, margin = v, isc.chord_gap
        if len(order) > _FINE_ABOVE:
            # many alike (the same cam phase every turn): sorted out first on polygons 8 times finer, as the
            # clearance audit does
            fine = ImperfectScene.from_scene(Scene(build_drive(drive.design, tol=drive.tol / 8)), imp)
            vf = np.empty(len(order))
            for s in np.unique(si[order]):
                m = np.nonzero(si[order] == s)[0]
                for a in range(0, len(m), _CHUNK):
                    mm = m[a : a + _CHUNK]
                    rot, shift = _poses(drive, imp, isc, ph[order[mm]], k[order[mm]], perfect_gaps[s][1])
                    vf[mm] = clearance_at_poses(fine, rot, shift).min
            vr, margin = np.full(len(v), np.inf), fine.chord_gap
            vr[order] = vf
            order = order[np.argsort(vf, kind="stable")]
            order = order[vr[order] - margin <= vr[order[0]] + margin]
        gap, at = np.inf, 0
        while at < len(order) and vr[order[at]] - margin < gap:
            b = order[at : at + _REFINE_BATCH]
            b = b[vr[b] - margin < gap]
            for s in np.unique(si[b]):
                sel = b[si[b] == s]
                rot, shift = _poses(drive, imp, isc, ph[sel], k[sel], perfect_gaps[s][1])
                vals = refine_min(isc, rot, shift, clearance_at_poses(isc, rot, shift)).min
                j = int(np.argmin(vals))
                if vals[j] < gap:
                    gap, best = float(vals[j]), int(sel[j])
            at += _REFINE_BATCH
    else:
        gap = float(v[best])
    out.update(gap=gap, gap_phi_h=float(ph[best]), gap_tooth=int(k[best]), gap_z=perfect_gaps[si[best]][1])
    out["gap_tooth_angle"] = float(2 * pi * k[best] / scene.z_g + c * ph[best])
    if perfect_pinch is not None:
        out.update(_pinch(drive, imp, isc, scene, perfect_gaps, perfect_pinch, shifts, refine))
    return out


def _pinch(drive, imp, isc, scene, perfect_gaps, perfect_pinch, shifts, refine):
    """The smallest clearance over each passage's window around the perfect pinch, moved by its crossing shift."""
    c = 1.0 / scene.ratios["u_hg"] - 1.0
    p_pin = perfect_pinch[1]
    offs = np.linspace(-PINCH_HALF, PINCH_HALF, 5)  # tooth-angle offsets: the pinch grid's step
    # Lipschitz constant of a passage's clearance in the generator angle: the perfect tooth's speed over every
    # tooth angle a window can reach, times |c|, plus how fast the errors move it (each first-harmonic term turns
    # at most once per generator turn relative to the tooth, so by at most its amplitude per radian)
    reach = np.linspace(p_pin - CROSS_WINDOW - PINCH_HALF, p_pin + CROSS_WINDOW + PINCH_HALF, 321)
    amp = imp.amplitude * (1.0 + abs(c))
    speed = {si: isc.speed_bound(reach, perfect_gaps[si][1]) * abs(c) + amp for si in shifts}
    cand = []
    for si, (ph0, k, dph) in shifts.items():
        z = perfect_gaps[si][1]
        p0 = perfect_gaps[si][0][1]
        ok = np.isfinite(dph)
        # the passage's generator angle at the perfect pinch's tooth angle, moved by its crossing shift
        centre = ph0[ok] + (p_pin - p0) / c + dph[ok]
        G = len(offs)
        ko = k[ok]
        v = np.empty((len(centre), G))
        for a in range(0, len(centre), _CHUNK):
            phs = centre[a : a + _CHUNK, None] + offs[None, :] / c
            rot, shift = _poses(drive, imp, isc, phs.ravel(), np.repeat(ko[a : a + _CHUNK], G), z)
            v[a : a + _CHUNK] = clearance_at_poses(isc, rot, shift).min.reshape(-1, G)
        cand.append((v.min(axis=1), v.min(axis=1) - 0.5 * speed[si] * (offs[1] - offs[0]) / abs(c), centre, ko, si))
    best = min(float(x[0].min()) for x in cand if len(x[0]))
    # passages whose window can hold a value below the best sampled one (Lipschitz between grid points)
    lo_, hi_, kk, ss, lbs = [], [], [], [], []
    for vmin, lb, centre, k, si in cand:
        sel = np.nonzero(lb < best + 2.0 * isc.chord_gap)[0]
        lo_.append(centre[sel] - PINCH_HALF / abs(c))
        hi_.append(centre[sel] + PINCH_HALF / abs(c))
        kk.append(k[sel])
        ss.append(np.full(len(sel), si))
        lbs.append(lb[sel])
    lo_, hi_, kk, ss, lbs = (np.concatenate(x) for x in (lo_, hi_, kk, ss, lbs))
    o = np.argsort(lbs, kind="stable")  # lowest bounds first: they set the bar for the rest
    lo_, hi_, kk, ss, lbs = lo_[o], hi_[o], kk[o], ss[o], lbs[o]

    def f(x, idx):
        vals = np.empty(len(x))
        for s in np.unique(ss[idx]):
            m = ss[idx] == s
            rot, shift = _poses(drive, imp, isc, x[m], kk[idx][m], perfect_gaps[s][1])
            vals[m] = clearance_at_poses(isc, rot, shift).min
        return vals

    V = np.array([speed[s] for s in ss])
    tol = 0.1 * drive.tol
    val, x, i = np.inf, np.nan, -1
    at = 0
    # windows in batches, lowest bounds first; a window whose bound is above the best found cannot hold it
    while at < len(lo_) and lbs[at] < val - tol:
        b = np.arange(at, min(len(lo_), at + _PINCH_BATCH))
        b = b[lbs[b] < val - tol]
        v_b, x_b, j = lipschitz_min(lambda x_, idx: f(x_, b[idx]), lo_[b], hi_[b], V[b], tol, n0=9)
        if v_b < val:
            val, x, i = v_b, x_b, int(b[j])
        at += _PINCH_BATCH
    if refine:
        z = perfect_gaps[ss[i]][1]
        w = 0.5 * (hi_[i] - lo_[i])
        p_c, val = x, np.inf
        for _ in range(4):
            g = np.clip(p_c + np.linspace(-w, w, 17), lo_[i], hi_[i])
            rot, shift = _poses(drive, imp, isc, g, np.full(17, kk[i]), z)
            v = refine_min(isc, rot, shift, clearance_at_poses(isc, rot, shift)).min
            j = int(np.argmin(v))
            if v[j] < val:
                val, p_c = float(v[j]), float(g[j])
            w /= 8.0
        x = p_c
    z = perfect_gaps[ss[i]][1]
    rot, shift = _poses(drive, imp, isc, np.array([x]), np.array([kk[i]]), z)
    det = clearance_at_poses(isc, rot, shift)
    rigid = det.lo if det.lower[0] <= det.upper[0] else det.up
    return {
        "pinch": float(val),
        "pinch_phi_h": float(x),
        "pinch_tooth": int(kk[i]),
        "pinch_z": z,
        "pinch_tooth_angle": float(2 * pi * kk[i] / scene.z_g + c * x),
        "pinch_rot": float(rot[0]),
        "pinch_shift": shift[0],
        "pinch_rigid": int(rigid[0]),
    }
