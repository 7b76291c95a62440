"""PNG figures of the kinematic error: KE over a revolution with its spectrum, KE against installation angle, double- vs single-flank errors (docs/models.md 6.1, 6.2)."""

from __future__ import annotations

import numpy as np

from wgcad.accuracy.flank_errors import ENGAGEMENTS, drive_flank_errors
from wgcad.placement.imperfect import full_cycle_turns
from wgcad.units import ARCSEC_PER_RAD

from .mpl import png_bytes
from .mpl import pyplot as _plt

__all__ = ["ke_png", "ke_figure", "install_png", "flank_png", "ke_load_png", "strands"]

_AS = ARCSEC_PER_RAD


def _png(fig, plt) -> bytes:
    return png_bytes(fig, tight_layout=True)


def ke_png(title: str, res, orders, amp, expected: dict, intrinsic=None, strongest=None) -> bytes:
    """KE over the record (arcsec against cam turns), its first mesh periods, and its spectrum with the expected
    orders and the ``strongest`` (``[(order, arcsec)]``, the summary's) marked."""
    plt = _plt()
    return _png(ke_figure(title, res, orders, amp, expected, intrinsic, strongest), plt)


def ke_figure(title: str, res, orders, amp, expected: dict, intrinsic=None, strongest=None):
    """The figure of :func:`ke_png`."""
    plt = _plt()
    fig, ax = plt.subplots(3, 1, figsize=(11, 10), dpi=90)
    turns = np.abs(res.phi_h) / (2 * np.pi)
    ax[0].plot(
        turns, res.ke * _AS, lw=0.4, color="k", label=f"KE ({res.engagement}), {res.ke_pp * _AS:.2f}'' peak to peak"
    )
    ax[0].set_xlabel("generator turns (one flexspline revolution)")
    ax[0].set_ylabel("KE, arcsec")
    ax[0].legend(fontsize=8, loc="upper right")
    ax[0].grid(alpha=0.3)
    # the first three mesh periods: the ripple of the tooth mesh itself
    n = min(len(res.ke), 3 * res.n_per_mesh * 4)
    deg = np.degrees(np.abs(res.phi_h[:n]))
    ax[1].plot(deg, res.ke[:n] * _AS, ".-", ms=3, lw=0.8, color="k", label="KE")
    if intrinsic is not None:
        m = min(n, len(intrinsic.ke))
        ax[1].plot(
            np.degrees(np.abs(intrinsic.phi_h[:m])),
            intrinsic.ke[:m] * _AS,
            ".-",
            ms=3,
            lw=0.8,
            color="tab:orange",
            label=f"perfect parts, {intrinsic.ke_pp * _AS:.3f}'' peak to peak",
        )
    ax[1].set_xlabel("generator angle, deg (the first mesh periods)")
    ax[1].set_ylabel("KE, arcsec")
    ax[1].legend(fontsize=8, loc="upper right")
    ax[1].grid(alpha=0.3)
    low = {k: v for k, v in expected.items() if k != "mesh"}
    strongest = [(float(o), float(a)) for o, a in (strongest or [])]
    top = max([max(low.values()) * 1.6] + [1.05 * o for o, _ in strongest if o < 2 * max(low.values())])
    sel = (orders > 0) & (orders <= top)
    a_sel = amp[sel] * _AS
    a_max = float(a_sel.max()) if a_sel.size else 1.0
    # four decades below the strongest order: what lies under that is noise of the sampling, not of the drive
    # (once: the axis ran over 8 decades down to a clamp at 1e-6)
    floor = 1e-4 * a_max
    ax[2].semilogy(orders[sel], np.maximum(a_sel, floor), lw=0.8, color="k", label="amplitude")
    ax[2].set_ylim(floor, 2.0 * a_max)
    # the expected orders in the legend, one entry per gear, not as text at the lines (close orders, e.g. the
    # rigid gear's 100 and the flexspline's 101, printed over each other)
    groups = {}
    for name, o in low.items():
        groups.setdefault("rigid" if name.startswith("rigid") else "flexspline", []).append(o)
    for (gear, os_), c in zip(sorted(groups.items()), ["tab:blue", "tab:red"]):
        for i, o in enumerate(os_):
            ax[2].axvline(
                o,
                color=c,
                ls="--",
                lw=0.8,
                alpha=0.7,
                label=f"{gear} orders: {', '.join(f'{x:g}' for x in os_)}" if i == 0 else None,
            )
    shown = [(o, a) for o, a in strongest if 0 < o <= top]
    if shown:
        # the summary's strongest orders where they are (D2's 300 and 301, the second strongest, were unmarked)
        ax[2].plot(
            [o for o, _ in shown],
            [2.0 * max(a, floor) for _, a in shown],
            "v",
            color="tab:green",
            ms=7,
            label="strongest: " + ", ".join(f"{o:g} ({a:.3g}'')" for o, a in shown),
        )
        ax[2].set_ylim(floor, 5.0 * a_max)
    ax[2].legend(fontsize=8, loc="upper right")
    label = "order, cycles per flexspline revolution"
    if "mesh" in expected:
        mo = expected["mesh"]
        near = np.abs(orders - mo) <= 0.5
        ma = float(amp[near].max() * _AS) if near.any() else float("nan")
        label += f"  (mesh order {mo:g}, off the axis: {ma:.3g} arcsec)"
    ax[2].set_xlabel(label)
    ax[2].set_ylabel("amplitude, arcsec")
    ax[2].grid(alpha=0.3, which="both")
    fig.suptitle(title)
    return fig


def install_png(title: str, rigid_deg, rigid_pp, best_deg, best_pp, flex_deg=None, flex_pp=None) -> bytes:
    """Largest KE (arcsec) against the rigid gear's installation angle, and against the flexspline's angular position."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(9, 4.5), dpi=90)
    ax.plot(rigid_deg, np.asarray(rigid_pp) * _AS, "o-", ms=3, label="rigid gear installation angle")
    if flex_deg is not None:
        ax.plot(flex_deg, np.asarray(flex_pp) * _AS, "s-", ms=3, label="flexspline angular position")
    ax.plot(
        [best_deg], [best_pp * _AS], "r*", ms=12, label=f"best rigid angle {best_deg:.1f} deg: {best_pp * _AS:.1f}''"
    )
    ax.set_xlabel("angle, deg")
    ax.set_ylabel("largest KE, arcsec")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return _png(fig, plt)


#: plain names of the engagement types of [S2] in the figure's legend
_ENGAGEMENT_NAMES = {
    "double": "double-flank (both flanks in contact)",
    "single_left": "single-flank, working flanks",
    "single_right": "single-flank, the other flanks",
}


def flank_png(title: str, turns, errors: dict, zones=("major axis", "second wave")) -> bytes:
    """[S2]'s radial and tangential mesh errors (um) of both engagement types, per zone: the first two generator
    turns in detail (left) and, over the whole error cycle, half the peak-to-peak of each turn (right).

    ``errors``: ``{(zone index, engagement): FlankErrors}`` with arrays over ``turns``
    (:func:`wgcad.accuracy.drive_flank_errors`). The errors turn once or twice per generator turn: drawn raw over
    the whole cycle (100 turns on D2) the six curves filled one band; per turn, the beat of the rigid
    gear's order against the flexspline's shows as the amplitude's slow swell.
    """
    plt = _plt()
    fig, ax = plt.subplots(2, 2, figsize=(13, 8.2), dpi=110, sharex="col", gridspec_kw={"width_ratios": [1, 2]})
    styles = {
        "double": dict(lw=1.1, color="k"),
        "single_left": dict(lw=0.9, color="tab:red", alpha=0.85),
        "single_right": dict(lw=0.9, color="tab:blue", alpha=0.85),
    }
    turns = np.asarray(turns, dtype=float)
    detail = turns <= turns[0] + 2.0
    whole = np.floor(turns - turns[0]).astype(int)
    n_turns = int(whole.max()) if len(whole) else 0
    for (zi, eng), fe in errors.items():
        st = dict(styles[eng])
        if zi:
            st.update(ls="--")
        lab = f"{_ENGAGEMENT_NAMES[eng]}, {zones[zi]}"
        for row, val in ((0, 1e3 * np.asarray(fe.dR)), (1, 1e3 * np.asarray(fe.dT))):
            ax[row, 0].plot(turns[detail], val[detail], label=lab if row == 0 else None, **st)
            if n_turns >= 1:
                k = np.arange(n_turns)
                half_pp = np.array(
                    [0.5 * (val[whole == i].max() - val[whole == i].min()) if np.any(whole == i) else np.nan for i in k]
                )
                ax[row, 1].plot(k + 0.5, half_pp, **st)
    ax[0, 0].set_ylabel("radial mesh error dR, um")
    ax[1, 0].set_ylabel("tangential mesh error dT, um")
    ax[1, 0].set_xlabel("generator turns (the first two)")
    ax[0, 1].set_ylabel("dR: half the peak-to-peak of each turn, um")
    ax[1, 1].set_ylabel("dT: half the peak-to-peak of each turn, um")
    ax[1, 1].set_xlabel("generator turns (the whole error cycle)")
    for a in ax.ravel():
        a.grid(alpha=0.3)
    fig.legend(fontsize=8, loc="lower center", ncol=3, frameon=False)
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.09, 1, 0.96))
    return png_bytes(fig)  # laid out above, with room for the legend below the panels


def strands(turns: np.ndarray) -> int:
    """How many interleaved strands samples at ``turns`` (generator turns, evenly spaced) form: successive samples
    step the cam by a fraction of a turn, so every ``m``-th sample sees nearly the same cam phase and they lie on
    one smooth curve (1 when the step is a whole number of turns or there are too few samples)."""
    if len(turns) < 3:
        return 1
    frac = float(np.mod(turns[1] - turns[0], 1.0))
    frac = min(frac, 1.0 - frac)
    if frac < 1e-9:
        return 1
    return max(1, min(int(round(1.0 / frac)), len(turns) // 2))


def ke_load_png(title: str, res, loaded: list) -> bytes:
    """No-load KE over the revolution with the loaded KE at its whole mesh periods, one colour per torque, each drawn
    as its strands (the samples of one cam phase joined; arcsec against generator turns); single-zone samples
    ringed. Below: the share of the tooth torque the lesser engagement zone carries at each sample ([S4]'s
    explanation of a large KE: single-zone engagement)."""
    from wgcad.accuracy.ke_load import SINGLE_ZONE_SHARE

    plt = _plt()
    fig, (ax, az) = plt.subplots(
        2, 1, figsize=(11, 7.6), dpi=150, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]}
    )
    turns = np.abs(res.phi_h) / (2 * np.pi)
    ax.plot(
        turns, res.ke * _AS, lw=0.4, color="0.75", label=f"no load, every angle: {res.ke_pp * _AS:.2f}'' peak to peak"
    )
    m = 1
    if loaded:
        L = loaded[0]
        idx = L.periods * res.n_per_mesh
        nl = (res.ke[idx] - res.ke[idx[0]]) * _AS
        t = np.abs(L.phi_h) / (2 * np.pi)
        m = strands(t)
        for j in range(m):
            ax.plot(
                t[j::m],
                nl[j::m],
                "-s",
                ms=2.5,
                lw=0.8,
                mfc="none",
                color="k",
                label=f"no load at the loaded samples' angles: {nl.max() - nl.min():.2f}'' peak to peak"
                if j == 0
                else None,
            )
    for i, L in enumerate(loaded):
        t = np.abs(L.phi_h) / (2 * np.pi)
        for j in range(m):
            ax.plot(
                t[j::m],
                L.ke[j::m] * _AS,
                "-o",
                ms=2.0,
                lw=0.9,
                color=f"C{i}",
                label=f"{L.torque_nm:g} N m: {L.ke_pp * _AS:.2f}'' peak to peak at {len(L.ke)} whole mesh periods"
                if j == 0
                else None,
            )
        sz = L.single_zone
        if sz.any():
            ax.plot(
                t[sz],
                L.ke[sz] * _AS,
                "o",
                ms=6,
                mfc="none",
                mec=f"C{i}",
                lw=0.8,
                label=f"{L.torque_nm:g} N m single-zone ({100 * sz.mean():.0f} % of the samples)",
            )
        if L.zone_share.size:
            lesser = 100 * np.nanmin(L.zone_share, axis=1)
            order = np.argsort(t)
            az.plot(t[order], lesser[order], ".", ms=3, color=f"C{i}", label=f"{L.torque_nm:g} N m")
    az.axhline(
        100 * SINGLE_ZONE_SHARE, color="0.4", lw=0.8, ls="--", label=f"single-zone below {100 * SINGLE_ZONE_SHARE:g} %"
    )
    az.set_ylim(0, 52)
    az.set_ylabel("lesser zone's share\nof the tooth torque, %")
    az.set_xlabel("generator turns (one flexspline revolution)")
    az.legend(fontsize=8.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    az.grid(alpha=0.3)
    ax.set_ylabel("KE, arcsec (each curve from its first sample)")
    ax.legend(fontsize=8.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3)
    how = f"every {m}th sample joined: one line per cam phase" if m > 1 else "samples joined"
    ax.set_title(
        title + f"\n(samples at whole mesh periods, {how}: a stroboscopic view of the cam-order content)", fontsize=10
    )
    return _png(fig, plt)


def ke_pngs(run) -> dict:
    """The pictures of a KE run (:class:`wgcad.services.ke.KERun`) as ``{suffix: PNG bytes}``: ``_ke``, ``_flank``
    and, where computed, ``_ke_load`` and ``_install``."""
    drive, imp = run.drive, run.imp
    d = drive.design.drive
    top = [(t["order"], t["amplitude_arcsec"]) for t in run.doc.get("spectrum_top", [])[:4]]
    out = {
        "_ke": ke_png(f"{d.name}: kinematic error, no load", run.res, run.orders, run.amp, run.expected, run.intr, top)
    }
    if run.loaded:
        out["_ke_load"] = ke_load_png(
            f"{d.name}: kinematic error under load (elastic model at whole mesh periods) and at no load",
            run.res,
            run.loaded,
        )
    if run.scan is not None:
        s = run.scan
        out["_install"] = install_png(
            f"{d.name}: largest KE against installation angle", s[0], s[1], s[2], s[3], s[0], s[4]
        )
    # [S2]'s model on the drive's own errors (docs/models.md 6.1) over the whole error cycle
    cyc = full_cycle_turns(d.z_flex, d.z_rigid)
    sgn = 1.0 if d.rotation == "ccw" else -1.0
    turns = np.linspace(0.0, cyc, 200 * cyc + 1)
    errs = {
        (zi, eng): drive_flank_errors(drive, imp, sgn * 2 * np.pi * turns, eng, zone=zone)
        for zi, zone in enumerate((0.0, np.pi))
        for eng in ENGAGEMENTS
    }
    out["_flank"] = flank_png(
        f"{d.name}: mesh errors of [S2]'s model, from the design's errors (docs/models.md 6.1)", turns, errs
    )
    return out
