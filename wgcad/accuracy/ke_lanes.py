"""The contact table's linear error terms and the first contact of every sample (docs/models.md 7).

Every contact's closing rotation moves with the errors by first harmonics
over the teeth and the generator angle: three complex waves shared by all
contacts (:func:`harmonics`, :func:`harmonic_terms`; :func:`error_terms`
term by term, the reference). Per lattice class only the contacts that can
be the first to touch are kept (:func:`candidate_lanes`), and in blocks of
samples only those whose chord can come lowest are evaluated
(:func:`lane_minimum`). ``tab`` is a :class:`wgcad.accuracy.ke_table.ContactTable`.
"""

from __future__ import annotations

from math import pi

import numpy as np

from ..kinematics import gear_ratios
from ..placement.imperfect import Imperfections, cam_offset, flex_deviations, rigid_deviations, rigid_translation

__all__ = [
    "N_WAVES",
    "LanePlan",
    "candidate_lanes",
    "error_terms",
    "fold_angle",
    "harmonic_terms",
    "harmonics",
    "lane_minimum",
]


def fold_angle(x):
    """Angles wrapped into ``[-pi, pi)``."""
    return (x + pi) % (2 * pi) - pi


def _geometry(tab, side: int, i: np.ndarray, e: np.ndarray) -> dict:
    """Per (sample, contact): flexspline tooth ``k``, rigid shift ``sb`` and ``R(rho) nt`` in the actual frame."""
    S = tab.sides[side]
    N, z_g, z_b = tab.N, tab.z_g, tab.z_b
    m = S["m"][e]
    M = z_g * N
    k = ((m + tab.sigma * i) % M) // N  # the flexspline tooth (material index)
    # the table frame turned to the actual one by whole rigid pitches: (m' + sigma i) / N, with m'
    # the lattice index of the folded tooth angle (docs/models.md 7: phi z_g / z_b + phi_h)
    sb = (((m + M // 2) % M - M // 2) + tab.sigma * i) // N
    # rho = 2 pi sb / z_b: its cosine and sine looked up per whole rigid pitch (no trigonometry per sample)
    ang = (2 * pi / z_b) * np.arange(z_b)
    cr, sr = np.cos(ang)[sb % z_b], np.sin(ang)[sb % z_b]
    ntx, nty = S["nt"][e, 0], S["nt"][e, 1]
    return {"k": k, "sb": sb, "nx": cr * ntx - sr * nty, "ny": sr * ntx + cr * nty}


def error_terms(tab, side: int, imp: Imperfections, i: np.ndarray, e: np.ndarray, which: str, geo=None) -> np.ndarray:
    """One group of linear error terms of the closing rotation, for samples ``i`` (I, 1) and contacts ``e`` (I, C)."""
    S = tab.sides[side]
    z_g, z_b = tab.z_g, tab.z_b
    geo = _geometry(tab, side, i, e) if geo is None else geo
    nx, ny = geo["nx"], geo["ny"]
    if which == "rigid":
        T = rigid_translation(imp)
        j = (S["j"][e] + geo["sb"]) % z_b
        # per-tooth values looked up (the same formula at the same whole tooth numbers): no sine per sample
        return T[0] * nx + T[1] * ny + rigid_deviations(imp, np.arange(z_b), z_b, tab.r_b)[j] * S["a_beta"][e]
    if which == "flex":
        da, dr = flex_deviations(imp, np.arange(z_g), z_g, tab.r_g)
        k = geo["k"]
        return -da[k] * S["a_phi"][e] - dr[k] * S["a_rho"][e]
    phi_h = tab.sigma * i * (2 * pi / (z_b * tab.N))
    E = cam_offset(imp, phi_h, phi_h / gear_ratios(z_g, z_b)["u_hg"], parts=("flex", "fixed"))
    return -S["c"][e] * (E[..., 0] * nx + E[..., 1] * ny)


#: the linear error terms as first harmonics: ``Re(A[e] . w(i))`` with one wave per column of :func:`_waves`
N_WAVES = 3


def _waves(tab, i: np.ndarray) -> np.ndarray:
    """The three waves the linear error terms of every contact are made of, ``(I, 3)`` complex, for samples ``i``.

    With ``s`` the whole rigid pitches the lattice has turned by at sample
    ``i`` (``s N = cls + sigma i``, exact), ``e^{2 pi i s / z_b}`` (rigid gear,
    stationary cam offset, and the normals turning with the rigid pitches),
    ``e^{2 pi i s / z_g}`` (flexspline teeth) and ``e^{i (2 pi s / z_b -
    phi_g)}`` (the flexspline-borne cam offset seen along a normal).
    """
    N = tab.N
    i = np.asarray(i)
    s = ((-tab.sigma * i) % N + tab.sigma * i) // N
    phi_h = tab.sigma * i * (2 * pi / (tab.z_b * N))
    phi_g = phi_h / gear_ratios(tab.z_g, tab.z_b)["u_hg"]
    ab, ag = 2 * pi * s / tab.z_b, 2 * pi * s / tab.z_g
    return np.exp(1j * np.stack([ab, ag, ab - phi_g], axis=-1))


def harmonics(tab, side: int, imp: Imperfections, groups=("cam", "rigid", "flex")) -> np.ndarray:
    """Each contact's linear error terms (the ``groups`` of :func:`error_terms`) as coefficients of :func:`_waves`, ``(E, 3)``.

    :func:`error_terms` of contact ``e`` at sample ``i`` equals ``Re(A[e] @ w(i))``
    (every error is a first harmonic over the teeth or the generator angle:
    docs/models.md 6.2); a contact of lattice index ``m`` stands at ``sb =
    q + s`` rigid pitches and on flexspline tooth ``k = p + s`` (mod ``z_g``),
    ``q, p`` its own. ``tests/test_ke.py`` holds it to :func:`error_terms`.
    """
    S = tab.sides[side]
    N, z_g, z_b = tab.N, tab.z_g, tab.z_b
    M = z_g * N
    m = S["m"]
    cls = m % N
    q = (((m + M // 2) % M - M // 2) - cls) // N
    p = (m - cls) // N
    nt = (S["nt"][:, 0] + 1j * S["nt"][:, 1]) * np.exp(2j * pi * q / z_b)  # the normal at s = 0
    A = np.zeros((len(m), N_WAVES), dtype=complex)
    if "rigid" in groups:
        tp = imp.rigid_ecc_phase + imp.rigid_install
        T = imp.rigid_ecc * np.exp(1j * tp)
        A_b = 0.5 * imp.rigid_runout / tab.r_b
        # T . n + dev_b[j] a_beta, j = j_e + q + s, dev_b = A_b sin((j + 1/2) 2 pi / z_b - gamma + xi)
        A[:, 0] += np.conj(T) * nt
        A[:, 0] += (
            S["a_beta"]
            * (-1j)
            * A_b
            * np.exp(1j * (imp.rigid_runout_phase - imp.rigid_install) + 2j * pi * (S["j"] + q + 0.5) / z_b)
        )
    if "flex" in groups:
        g = imp.flex_install
        A1 = 0.5 * imp.flex_runout / tab.r_g
        Ec = imp.flex_ecc * np.exp(-1j * (imp.flex_ecc_phase + g))
        # -dalpha[k] a_phi - drho[k] a_rho at a = 2 pi k / z_g: dalpha = Im(c_a e^{ia}), drho = Re(Ec e^{ia})
        c_a = A1 * np.exp(1j * (imp.flex_runout_phase - g)) - (imp.flex_ecc / tab.r_g) * np.exp(
            -1j * (imp.flex_ecc_phase + g)
        )
        A[:, 1] += np.exp(2j * pi * p / z_g) * (-S["a_phi"] * (-1j) * c_a - S["a_rho"] * Ec)
    if "cam" in groups:
        # -c (E . n): the stationary part with the normal's wave, the flexspline-borne one turning with phi_g
        A[:, 0] += -S["c"] * np.conj(imp.cam_fixed * np.exp(1j * imp.cam_fixed_phase)) * nt
        A[:, 2] += -S["c"] * imp.cam_flex * np.exp(-1j * imp.cam_flex_phase) * nt
    return A


def harmonic_terms(tab, lanes: np.ndarray, A: np.ndarray, i: np.ndarray) -> np.ndarray:
    """``Re(A[e] . w(i))`` for samples ``i`` and their lanes' contacts, ``(I, C)`` (padding: 0).

    One real matrix product per lattice class: ``[Re w, -Im w] @ [Re A; Im A]``.
    """
    i = np.asarray(i)
    N = tab.N
    out = np.zeros((len(i), lanes.shape[1]))
    W = _waves(tab, i)
    Wr = np.concatenate([W.real, -W.imag], axis=1)
    r_of = i % N
    for r in np.unique(r_of):
        rows = np.nonzero(r_of == r)[0]
        e = lanes[r]
        ok = e >= 0
        Ar = A[np.where(ok, e, 0)]
        Ar = np.concatenate([Ar.real, Ar.imag], axis=1).T * ok
        out[rows] = Wr[rows] @ Ar
    return out


#: samples of one lattice class per block of :func:`lane_minimum`
_BLOCK = 16
#: stretches of samples whose waves a table keeps (:class:`LanePlan`)
_WAVE_CACHE = 8


def _rates(tab) -> np.ndarray:
    """How fast each wave of :func:`_waves` turns from one sample of a lattice class to its next (``i + N``), rad."""
    u = gear_ratios(tab.z_g, tab.z_b)["u_hg"]
    wb, wg = 2 * pi * tab.sigma / tab.z_b, 2 * pi * tab.sigma / tab.z_g
    return np.abs(np.array([wb, wg, wb - wb / u]))


class LanePlan:
    """What :func:`lane_minimum` needs of samples ``i`` and ``lanes`` whatever the errors: per lattice class the
    rows in blocks of ``block``, the waves at every row and at each block's two ends (built once, reused for
    every installation angle of a scan)."""

    def __init__(self, tab, lanes: np.ndarray, i: np.ndarray, block: int = _BLOCK):
        i = np.asarray(i)
        self.n_samples = len(i)
        # a wave's term strays from the chord between the block's ends by at most |A| rate^2 (block - 1)^2 / 8
        self.bend = _rates(tab) ** 2 * (block - 1) ** 2 / 8.0
        self.classes = []
        self.rows = []  # per class, (B, block) sample rows of its blocks
        self.r = []  # per class, its residue
        # the waves of a stretch of samples do not depend on the errors: kept with the table for the next
        # drive of a sweep (a few MB per 2**16 samples)
        key = (int(i[0]), len(i), block) if len(i) and np.array_equal(i, np.arange(i[0], i[0] + len(i))) else None
        cache = tab.__dict__.setdefault("_wave_cache", {})
        waves = cache.get(key) if key is not None else None
        if waves is None:
            waves = {}
            r_of = i % tab.N
            for r in np.unique(r_of):
                rows = np.nonzero(r_of == r)[0]  # consecutive samples of the class, in order
                n = len(rows)
                nb = -(-n // block)
                rr = np.concatenate([rows, np.full(nb * block - n, rows[-1])]).reshape(nb, block)
                W = _waves(tab, i[rr.ravel()]).reshape(nb, block, N_WAVES)
                # the block's two ends (a padded block ends at its last real sample)
                last = (np.minimum(np.arange(nb) * block + block, n) - 1) - np.arange(nb) * block
                ends = np.stack([W[:, 0, :], W[np.arange(nb), last, :]], axis=1)
                waves[int(r)] = (rows, rr, ends, np.concatenate([W.real, -W.imag], axis=2))
            if key is not None:
                if len(cache) >= _WAVE_CACHE:
                    cache.pop(next(iter(cache)))
                cache[key] = waves
        for r, (rows, rr, ends, Wr) in waves.items():
            e = lanes[r]
            e = e[e >= 0]
            if e.size == 0:
                continue
            self.classes.append((rows, e, ends, Wr))
            self.rows.append(rr)
            self.r.append(r)


def lane_minimum(
    tab,
    lanes: np.ndarray,
    g: np.ndarray,
    A: np.ndarray,
    i: np.ndarray,
    block: int = _BLOCK,
    plan: LanePlan | None = None,
):
    """The first contact of each sample: ``min_e g[e] + Re(A[e] . w(i))`` over its lanes, and which ``e`` it is.

    Exact, and cheaper than every lane at every sample: the samples of one
    lattice class follow each other as ``t`` steps and each wave turns by a
    fixed angle per step (:func:`_rates`), so within a block of ``block``
    samples a contact's value strays from the chord between its values at
    the block's two ends by at most ``c_e = sum_f |A_ef| rate_f^2 (block -
    1)^2 / 8``. A contact whose chord lies above the chord of the block's
    best-bounded contact by more than both strays, at both ends (chords are
    straight: then everywhere between), is never the smallest in that
    block; the rest are evaluated at every sample of the block. ``plan``:
    :class:`LanePlan` of ``lanes`` and ``i``.

    Returns
    -------
    value : (I,) float
        inf where a sample has no contact.
    first : (I,) int
        Contact index, -1 where none.
    """
    plan = LanePlan(tab, lanes, i, block) if plan is None else plan
    val = np.full(plan.n_samples, np.inf)
    first = np.full(plan.n_samples, -1, dtype=int)
    bend = np.abs(A) @ plan.bend
    for c, (rows, e, ends, Wr) in enumerate(plan.classes):
        ve, cb = _ends(g, A, bend, e, ends)
        star = np.argmin(ve.max(axis=1) + cb, axis=1)  # the lane with the lowest upper bound over the block
        rb = np.arange(len(ve))
        gap = ve - ve[rb, :, star][:, :, None]
        keep = ~np.all(gap > (cb[None, :] + cb[star][:, None] + 1e-15)[:, None, :], axis=1)
        K = int(keep.sum(axis=1).max())
        # the kept lanes of each block first; a block with fewer fills up with others (real lanes: harmless)
        order = np.argsort(~keep, axis=1, kind="stable")[:, :K]
        sel = e[order]
        Ak = A[sel]
        v = g[sel][:, None, :] + Wr @ np.concatenate([Ak.real, Ak.imag], axis=2).transpose(0, 2, 1)
        j = np.argmin(v, axis=2)
        at = plan.rows[c]  # (B, block) rows, a padded block repeating its last
        val[at] = np.take_along_axis(v, j[:, :, None], axis=2)[:, :, 0]
        first[at] = np.take_along_axis(sel, j, axis=1)
    return val, first


def _ends(g, A, bend, e, ends):
    """Every lane ``e`` at the blocks' two ends, ``(B, 2, E)``, and how far each can stray from its chord, ``(E,)``."""
    return g[e][None, None, :] + (ends @ A[e].T).real, bend[e]


def candidate_lanes(tab, side: int, imp: Imperfections, slack: float = 1.05) -> np.ndarray:
    """Candidate contacts per lattice class (N, C), padded with -1: those that can be the first to touch.

    Within a group (one zone, one section) the errors move neighbouring teeth
    almost alike: ``|Delta_e - Delta_e*| <= D_e`` (bounded term by term from
    the amplitudes and the differences of the contacts' sensitivities and of
    the teeth's positions), so a contact whose perfect closing rotation
    exceeds the group's smallest, ``g_e*``, by more than ``D_e`` is never first.
    Across groups the whole error bound ``B`` prunes.
    """
    S = tab.sides[side]
    z_g, z_b, N = tab.z_g, tab.z_b, tab.N
    ntn = np.hypot(S["nt"][:, 0], S["nt"][:, 1])
    A_b = 0.5 * imp.rigid_runout / tab.r_b
    A_a = (0.5 * imp.flex_runout + imp.flex_ecc) / tab.r_g
    Vmax = imp.rigid_ecc + S["c"] * (imp.cam_flex + imp.cam_fixed)
    B = Vmax * ntn + A_b * np.abs(S["a_beta"]) + A_a * np.abs(S["a_phi"]) + imp.flex_ecc * np.abs(S["a_rho"])
    B = B * slack + 1e-12  # 5 % for the linearisation's second order (2x before the sensitivities are refined)
    M = z_g * N
    phi = fold_angle(2 * pi * S["m"] / M)
    zone = np.where(np.abs(phi) <= 0.5 * pi, 0, 1)  # 0: the zone around +x, 1: around -x (two waves)
    cls = (-tab.sigma * np.arange(N)) % N  # lattice class of sample residue r
    mf = (S["m"] + M // 2) % M - M // 2  # folded lattice index
    cq = np.round(S["c"] * 1e6).astype(int)
    group = np.unique(np.stack([zone, cq], 1), axis=0, return_inverse=True)[
        1
    ].ravel()  # (zone, section) of each contact
    out = []
    for r in range(N):
        e = np.nonzero(S["m"] % N == cls[r])[0]
        if e.size == 0:
            out.append(e)
            continue
        keep = S["g"][e] - B[e] <= np.min(S["g"][e] + B[e])
        for gk in np.unique(group[e]):
            sel = group[e] == gk
            grp = e[sel]
            es = grp[np.argmin(S["g"][grp])]
            dk = np.abs(mf[grp] - mf[es]) // N  # teeth apart (same class: a whole number)
            dj = np.abs(((S["j"][grp] - S["j"][es] + (mf[grp] - mf[es]) // N) + z_b // 2) % z_b - z_b // 2)
            dnt = np.hypot(*(S["nt"][grp] - S["nt"][es]).T)
            D = (
                Vmax[grp] * (dnt + ntn[es] * 2 * pi * dk / z_b)
                + A_b * (np.abs(S["a_beta"][grp] - S["a_beta"][es]) + np.abs(S["a_beta"][es]) * 2 * pi * dj / z_b)
                + A_a * (np.abs(S["a_phi"][grp] - S["a_phi"][es]) + np.abs(S["a_phi"][es]) * 2 * pi * dk / z_g)
                + imp.flex_ecc * (np.abs(S["a_rho"][grp] - S["a_rho"][es]) + np.abs(S["a_rho"][es]) * 2 * pi * dk / z_g)
            )
            far = S["g"][grp] - S["g"][es] > slack * D + 1e-12
            keep[np.nonzero(sel)[0][far]] = False
        out.append(e[keep])
    C = max(len(x) for x in out)
    lanes = np.full((N, max(C, 1)), -1, dtype=int)
    for r, x in enumerate(out):
        lanes[r, : len(x)] = x
    return lanes
