"""The contact table's linear error terms and the first contact of every sample (docs/models.md 7).

Every contact's closing rotation moves with the errors by first harmonics
over the teeth and the generator angle: three complex waves shared by all
contacts (:func:`harmonics`, :func:`harmonic_terms`; :func:`error_terms`
term by term, the reference). Per lattice class only the contacts that can
be the first to touch are kept (:func:`candidate_lanes`); of those, the
ones no other contact of the class stays below at every sample
(:func:`undominated`) are evaluated at every sample (:func:`first_contacts`).
The earlier search, block by block among the lanes whose chord can come
lowest (:func:`lane_minimum`), stays as the reference and for the
installation-angle scan. ``tab`` is a :class:`wgcad.accuracy.ke_table.ContactTable`.
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
    "class_waves",
    "error_terms",
    "first_contacts",
    "fold_angle",
    "harmonic_terms",
    "harmonics",
    "lane_minimum",
    "undominated",
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


def harmonics(tab, side: int, imp: Imperfections, groups=("cam", "rigid", "flex"), contacts=None) -> np.ndarray:
    """Each contact's linear error terms (the ``groups`` of :func:`error_terms`) as coefficients of :func:`_waves`, ``(E, 3)``.

    :func:`error_terms` of contact ``e`` at sample ``i`` equals ``Re(A[e] @ w(i))``
    (every error is a first harmonic over the teeth or the generator angle:
    docs/models.md 6.2); a contact of lattice index ``m`` stands at ``sb =
    q + s`` rigid pitches and on flexspline tooth ``k = p + s`` (mod ``z_g``),
    ``q, p`` its own. ``tests/test_ke.py`` holds it to :func:`error_terms`.
    ``contacts``: only those rows (the same values), ``(len(contacts), 3)``.
    """
    F = _harmonic_factors(tab, side)
    if contacts is not None:
        F = {k: v[contacts] for k, v in F.items()}
    nt = F["nt"]  # the normal at s = 0
    A = np.zeros((len(nt), N_WAVES), dtype=complex)
    if "rigid" in groups:
        tp = imp.rigid_ecc_phase + imp.rigid_install
        T = imp.rigid_ecc * np.exp(1j * tp)
        A_b = 0.5 * imp.rigid_runout / tab.r_b
        # T . n + dev_b[j] a_beta, j = j_e + q + s, dev_b = A_b sin((j + 1/2) 2 pi / z_b - gamma + xi)
        A[:, 0] += np.conj(T) * nt
        A[:, 0] += F["a_beta_i"] * A_b * np.exp(1j * (imp.rigid_runout_phase - imp.rigid_install) + F["rigid_arg"])
    if "flex" in groups:
        g = imp.flex_install
        A1 = 0.5 * imp.flex_runout / tab.r_g
        Ec = imp.flex_ecc * np.exp(-1j * (imp.flex_ecc_phase + g))
        # -dalpha[k] a_phi - drho[k] a_rho at a = 2 pi k / z_g: dalpha = Im(c_a e^{ia}), drho = Re(Ec e^{ia})
        c_a = A1 * np.exp(1j * (imp.flex_runout_phase - g)) - (imp.flex_ecc / tab.r_g) * np.exp(
            -1j * (imp.flex_ecc_phase + g)
        )
        A[:, 1] += F["flex_wave"] * (F["a_phi_i"] * c_a - F["a_rho"] * Ec)
    if "cam" in groups:
        # -c (E . n): the stationary part with the normal's wave, the flexspline-borne one turning with phi_g
        A[:, 0] += F["minus_c"] * np.conj(imp.cam_fixed * np.exp(1j * imp.cam_fixed_phase)) * nt
        A[:, 2] += F["minus_c"] * imp.cam_flex * np.exp(-1j * imp.cam_flex_phase) * nt
    return A


def _harmonic_factors(tab, side: int) -> dict:
    """The parts of :func:`harmonics` that do not depend on the errors, per contact (kept with the table)."""
    cache = tab.__dict__.setdefault("_harmonic_factors", {})
    if side not in cache:
        S = tab.sides[side]
        N, z_g, z_b = tab.N, tab.z_g, tab.z_b
        M = z_g * N
        m = S["m"]
        cls = m % N
        q = (((m + M // 2) % M - M // 2) - cls) // N
        p = (m - cls) // N
        cache[side] = {
            "nt": (S["nt"][:, 0] + 1j * S["nt"][:, 1]) * np.exp(2j * pi * q / z_b),
            "a_beta_i": S["a_beta"] * (-1j),
            "rigid_arg": 2j * pi * (S["j"] + q + 0.5) / z_b,
            "flex_wave": np.exp(2j * pi * p / z_g),
            "a_phi_i": -S["a_phi"] * (-1j),
            "a_rho": S["a_rho"],
            "minus_c": -S["c"],
        }
    return cache[side]


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
    Across groups the whole error bound ``B`` prunes. Both bounds are sums of
    the amplitudes times per-contact factors that do not depend on the errors
    (:func:`_lane_factors`, kept with the table): one pass over the contacts.
    """
    S = tab.sides[side]
    f = _lane_factors(tab, side)
    A_b = 0.5 * imp.rigid_runout / tab.r_b
    A_a = (0.5 * imp.flex_runout + imp.flex_ecc) / tab.r_g
    Vmax = imp.rigid_ecc + S["c"] * (imp.cam_flex + imp.cam_fixed)
    B = Vmax * f["ntn"] + A_b * f["abs_beta"] + A_a * f["abs_phi"] + imp.flex_ecc * f["abs_rho"]
    B = B * slack + 1e-12  # 5 % for the linearisation's second order (2x before the sensitivities are refined)
    X = f["group"]
    D = Vmax * X[0] + A_b * X[1] + A_a * X[2] + imp.flex_ecc * X[3]
    far = f["above_best"] > slack * D + 1e-12
    order, sizes = f["order"], f["sizes"]  # the contacts class by class, ascending within each
    full = sizes > 0
    starts = (np.cumsum(sizes) - sizes)[full]
    g, B = S["g"][order], B[order]
    kept = np.zeros(tab.N, dtype=int)
    keep = np.zeros(len(order), dtype=bool)
    if len(order):
        keep = (g - B <= np.repeat(np.minimum.reduceat(g + B, starts), sizes[full])) & ~far[order]
        kept[full] = np.add.reduceat(keep, starts)
    lanes = np.full((tab.N, max(int(kept.max()), 1)), -1, dtype=int)
    col = np.arange(int(kept.sum())) - np.repeat(np.cumsum(kept) - kept, kept)
    lanes[np.repeat(np.arange(tab.N), sizes)[keep], col] = order[keep]
    return lanes


def _lane_factors(tab, side: int) -> dict:
    """What :func:`candidate_lanes` multiplies the amplitudes by, per contact, and the contacts' order by class.

    ``group`` (4, E): the factors of ``D_e`` against the contact's group's best
    ``e*`` (translation, rigid and flexspline tooth rotation, flexspline
    eccentricity); ``above_best``: ``g_e - g_e*``. Kept with the table (they
    depend on its contacts only).
    """
    cache = tab.__dict__.setdefault("_lane_factors", {})
    if side in cache:
        return cache[side]
    S = tab.sides[side]
    z_g, z_b, N = tab.z_g, tab.z_b, tab.N
    ntn = np.hypot(S["nt"][:, 0], S["nt"][:, 1])
    M = z_g * N
    phi = fold_angle(2 * pi * S["m"] / M)
    zone = np.where(np.abs(phi) <= 0.5 * pi, 0, 1)  # 0: the zone around +x, 1: around -x (two waves)
    cls = (-tab.sigma * np.arange(N)) % N  # lattice class of sample residue r
    mf = (S["m"] + M // 2) % M - M // 2  # folded lattice index
    cq = np.round(S["c"] * 1e6).astype(int)
    group = np.unique(np.stack([zone, cq], 1), axis=0, return_inverse=True)[
        1
    ].ravel()  # (zone, section) of each contact
    X = np.zeros((4, len(S["g"])))
    above = np.zeros(len(S["g"]))
    order = []
    for r in range(N):
        e = np.nonzero(S["m"] % N == cls[r])[0]
        order.append(e)
        for gk in np.unique(group[e]):
            grp = e[group[e] == gk]
            es = grp[np.argmin(S["g"][grp])]
            dk = np.abs(mf[grp] - mf[es]) // N  # teeth apart (same class: a whole number)
            dj = np.abs(((S["j"][grp] - S["j"][es] + (mf[grp] - mf[es]) // N) + z_b // 2) % z_b - z_b // 2)
            X[0, grp] = np.hypot(*(S["nt"][grp] - S["nt"][es]).T) + ntn[es] * 2 * pi * dk / z_b
            X[1, grp] = np.abs(S["a_beta"][grp] - S["a_beta"][es]) + np.abs(S["a_beta"][es]) * 2 * pi * dj / z_b
            X[2, grp] = np.abs(S["a_phi"][grp] - S["a_phi"][es]) + np.abs(S["a_phi"][es]) * 2 * pi * dk / z_g
            X[3, grp] = np.abs(S["a_rho"][grp] - S["a_rho"][es]) + np.abs(S["a_rho"][es]) * 2 * pi * dk / z_g
            above[grp] = S["g"][grp] - S["g"][es]
    cache[side] = out = {
        "ntn": ntn,
        "abs_beta": np.abs(S["a_beta"]),
        "abs_phi": np.abs(S["a_phi"]),
        "abs_rho": np.abs(S["a_rho"]),
        "group": X,
        "above_best": above,
        "order": np.concatenate(order).astype(int),
        "sizes": np.array([len(e) for e in order]),
    }
    return out


#: margin (rad) by which a contact must stay above another to be dropped as never first: far above the
#: rounding of the closing rotations (~1e-3 rad, ulp 2e-19) and of the bound's sums
_DOMINANCE_TOL = 1e-15


def undominated(lanes: np.ndarray, A: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Which lanes of each lattice class (``lanes`` (N, C), -1 padding) can be the first at any sample, (N, C) bool.

    Lane ``e`` at sample ``i`` is ``g_e + Re(A_e . w(i))`` with ``|w_f(i)| =
    1``, so ``e`` stays above lane ``d`` at every sample once ``g_e - g_d >
    sum_f |A_ef - A_df|``: the errors move two contacts of a class almost
    alike, and a handful of the ~150 candidates remain. Each class tries its
    remaining lanes as the lower one, lowest ``g`` first, until every
    remaining lane has been tried (after the first, on the survivors only).
    """
    ok = lanes >= 0
    rows = np.arange(len(lanes))
    col = np.broadcast_to(np.arange(lanes.shape[1]), lanes.shape)
    e = np.where(ok, lanes, 0)
    Ae, ge = A[e], np.where(ok, g[e], np.inf)
    alive, tried = ok.copy(), ~ok
    while True:
        open_ = alive & ~tried
        busy = open_.any(axis=1)
        if not busy.any():
            break
        d = np.argmin(np.where(open_, ge, np.inf), axis=1)
        spread = np.abs(Ae - Ae[rows, d][:, None, :]).sum(axis=2)
        with np.errstate(invalid="ignore"):  # inf - inf in a class without lanes (not busy: masked out)
            above = ge - ge[rows, d][:, None] > spread + _DOMINANCE_TOL
        alive &= ~(above & busy[:, None])
        tried[rows[busy], d[busy]] = True
        if alive.shape[1] > 2 * alive.sum(axis=1).max():  # most are gone: carry on with the survivors' columns
            keep = np.argsort(~alive, axis=1, kind="stable")[:, : max(int(alive.sum(axis=1).max()), 1)]
            col, Ae = np.take_along_axis(col, keep, 1), np.take_along_axis(Ae, keep[:, :, None], 1)
            ge, alive, tried = (np.take_along_axis(x, keep, 1) for x in (ge, alive, tried))
    out = np.zeros(lanes.shape, dtype=bool)
    out[np.broadcast_to(rows[:, None], col.shape)[alive], col[alive]] = True
    return out


def class_waves(tab, I: int) -> list:
    """The waves of :func:`_waves` as real rows ``[Re w, -Im w, 1]`` for samples ``0 .. I - 1``, per lattice class
    ``r``: ``(7, T_r)`` for samples ``r, r + N, ...``, so that ``[Re A, Im A, g] @ W = g + Re(A . w)`` (kept with
    the table for the next drive of a sweep)."""
    cache = tab.__dict__.setdefault("_class_waves", {})
    if I not in cache:
        W = _waves(tab, np.arange(I))
        Wr = np.concatenate([W.real, -W.imag, np.ones((I, 1))], axis=1)
        if len(cache) >= 2:
            cache.pop(next(iter(cache)))
        cache[I] = [np.ascontiguousarray(Wr[r :: tab.N].T) for r in range(tab.N)]
    return cache[I]


#: samples of a class per matrix product: the waves' stretch stays in cache for both sides (~17 % off at 4096
#: against whole classes, measured on D2's sweep samples)
_TILE = 4096


def first_contacts(tab, sides, I: int) -> list:
    """The first contact of samples ``0 .. I - 1`` on each side: ``min_e g[e] + Re(A[e] . w(i))`` over the
    :func:`undominated` lanes of each sample's class (the same minimum as over every lane).

    Parameters
    ----------
    sides : list of (lanes, g, A, flag)
        Per side its lanes (N, C), closing rotations (E,), coefficients (E, 3) and, or None, the contacts
        (E,) bool to report when first.

    Returns
    -------
    list of (value, flagged)
        Per side: (I,) float, inf where a sample has no contact; (I,) bool, whether the first contact is flagged.
    """
    N = tab.N
    W = class_waves(tab, I)
    T = -(-I // N)
    # class by class into rows (sample r + N t at [r, t]; the rows' ends past I stay empty), read out once
    out = []
    for lanes, g, A, flag in sides:
        # g last: the six products' sum, then + g, as lane_minimum rounds them (a BLAS that sums in order)
        Ar = np.concatenate([A.real, A.imag, g[:, None]], axis=1)
        out.append((lanes, undominated(lanes, A, g), Ar, flag, np.full((N, T), np.inf), np.zeros((N, T), dtype=bool)))
    for r in range(min(N, I)):
        rows = []
        for lanes, alive, Ar, flag, value, flagged in out:
            e = lanes[r][alive[r]]
            if e.size:
                rows.append((Ar[e], flag[e] if flag is not None and flag[e].any() else None, value[r], flagged[r]))
        for a in range(0, W[r].shape[1], _TILE):
            w = W[r][:, a : a + _TILE]
            b = a + w.shape[1]
            for Ae, fe, row_value, row_flagged in rows:
                v = Ae @ w
                np.min(v, axis=0, out=row_value[a:b])
                if fe is not None:
                    row_flagged[a:b] = fe[np.argmin(v, axis=0)]
    return [
        (value.T.ravel()[:I], flagged.T.ravel()[:I] if flagged.any() else np.zeros(I, dtype=bool))
        for *_, value, flagged in out
    ]
