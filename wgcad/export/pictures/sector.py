"""Pictures of a discrete-motion drive: tooth heights both ways, the motion law, the sectored audit (PNG bytes; matplotlib inside the functions)."""

from __future__ import annotations

import numpy as np

from .mpl import png_bytes, pyplot

__all__ = ["heights_png", "motion_png", "audit_png", "loaded_png"]


def _fig(nrows, figsize, **kw):
    plt = pyplot()
    fig, axs = plt.subplots(nrows, 1, figsize=figsize, dpi=100, **kw)
    return plt, fig, axs


def _png(plt, fig) -> bytes:
    return png_bytes(fig)


def _shade_sectors(ax, bounds_deg, kinds, lo, hi, shade=True):
    """Each sector's span shaded (coupling green, transmission orange) and named above the axes; ``shade=False``: the
    names only (over a picture whose shading means something else)."""
    for a, b, k in zip(bounds_deg[:-1], bounds_deg[1:], kinds):
        if hi <= a or lo >= b:
            continue
        if shade:
            ax.axvspan(max(a, lo), min(b, hi), color="tab:green" if k == "coupling" else "tab:orange", alpha=0.08, lw=0)
        ax.text(
            0.5 * (max(a, lo) + min(b, hi)),
            1.0,
            k,
            transform=ax.get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=8,
        )


def _per_sector(ax, c, vals, sector, sel, **kw):
    """One line per sector: a line between the last tooth of one sector and the first of the next would draw a ramp
    across the boundary that no tooth has."""
    label = kw.pop("label", None)
    for s in dict.fromkeys(sector[sel].tolist()):
        k = sel & (sector == s)
        ax.plot(c[k], vals[k], label=label, **kw)
        label = None


def heights_png(
    title: str,
    centres_deg,
    bounds_deg,
    kinds,
    full_mm: float,
    formula_mm,
    register_mm,
    simulated_mm,
    built_mm,
    tip_clearance_um: float = 0.0,
    sector=None,
) -> bytes:
    """Tooth heights over half the gear (one wave: a coupling and a transmission sector): [S5]'s formula with the axis
    on the boundary and with the register rule, simulated, built; and simulated less the formula. ``sector``: each
    tooth's sector (lines stop at the boundaries). A rule whose heights another's hide says so in its label."""
    plt, fig, (ax, ax2) = _fig(2, (11, 7.5), sharex=True, gridspec_kw={"height_ratios": [2.2, 1]})
    c = np.asarray(centres_deg)
    sector = np.zeros(len(c), int) if sector is None else np.asarray(sector)
    lo, hi = bounds_deg[0], bounds_deg[0] + 180.0
    sel = (c >= lo) & (c < hi)
    _shade_sectors(ax, np.asarray(bounds_deg), kinds, lo, hi)
    ax.axhline(1e3 * full_mm, color="0.5", lw=1, ls=":", label=f"full height {1e3 * full_mm:.1f} um")
    sim_label = f"simulated: largest keeping {tip_clearance_um:g} um tip clearance"
    reg_label = "formula at the out-of-register angle (register)"
    reg, sim = 1e3 * np.asarray(register_mm), 1e3 * np.asarray(simulated_mm)
    if np.all(np.abs(reg - sim)[sel] < 0.5):
        reg_label += ": under the simulated (within 0.5 um)"
    curves = (
        (
            1e3 * np.asarray(formula_mm),
            dict(marker="o", color="tab:blue", ms=4),
            "[S5] formula, major axis on the sector boundary (fig. 3)",
        ),
        (reg, dict(marker="^", color="tab:gray", ms=9, mfc="none", ls="--"), reg_label),
        (sim, dict(marker="s", color="tab:red", ms=4), sim_label),
    )
    for vals, style, label in curves:
        _per_sector(ax, c, vals, sector, sel, lw=1.1, label=label, **style)
    ax.plot(c[sel], 1e3 * np.asarray(built_mm)[sel], "x", color="k", ms=7, label="built")
    ax.set_ylabel("tooth height h_i, um (root to tip)")
    ax.set_ylim(0, 1e3 * full_mm * 1.12)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10, pad=16)
    d = sim - 1e3 * np.asarray(formula_mm)
    _shade_sectors(ax2, np.asarray(bounds_deg), kinds, lo, hi)
    _per_sector(ax2, c, d, sector, sel, marker="d", color="tab:purple", ms=4, lw=1)
    ax2.axhline(0.0, color="0.4", lw=0.8)
    ax2.set_ylabel("simulated - formula, um\n(> 0: the formula lowers more)", fontsize=9)
    ax2.set_xlabel("tooth centre angle on the rigid gear, deg (counter-clockwise; the other half is the same)")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return _png(plt, fig)


def loaded_png(title: str, phi_h_deg, deviation_arcsec, peak_n, lowered_n, bounds_deg, kinds, dwells_deg=()) -> bytes:
    """The loaded drive over half a turn: what the load adds to the output, and the largest tooth force (all teeth and
    lowered teeth), against the generator angle, sectors shaded; ``dwells_deg`` ((start, end) pairs): where the motion
    law holds the output still, marked under the first panel (a loaded output that changes there moves in the
    dwell)."""
    plt, fig, (ax, ax2) = _fig(2, (11, 7), sharex=True)
    x = np.asarray(phi_h_deg)
    lo, hi = float(x.min()) - 5.0, float(x.max()) + 5.0
    b = np.asarray(bounds_deg)
    for a in (ax, ax2):
        _shade_sectors(a, b, kinds, lo, hi)
    ax.plot(
        x, deviation_arcsec, "o-", color="tab:blue", ms=4, lw=1.2, label="settled states (the lines only join them)"
    )
    label = "the motion law's dwell (output still)"
    for a0, a1 in dwells_deg:
        if a1 > lo and a0 < hi:
            ax.plot(
                [max(a0, lo), min(a1, hi)],
                [0.03, 0.03],
                color="tab:green",
                lw=4,
                transform=ax.get_xaxis_transform(),
                label=label,
            )
            label = None
    ax.legend(fontsize=8, loc="upper center")
    ax.set_ylabel("loaded output - motion law, arcsec")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10, pad=16)
    ax2.plot(x, peak_n, "s-", color="tab:red", ms=4, lw=1.2, label="largest tooth force")
    ax2.plot(x, lowered_n, "^-", color="tab:gray", ms=4, lw=1, label="largest force on a lowered tooth")
    ax2.set_ylabel("normal force, N")
    ax2.set_xlabel("generator angle phi_h, deg (states at the motion law's knots, settled under the load)")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    ax2.set_xlim(lo, hi)
    fig.tight_layout()
    return _png(plt, fig)


def motion_png(title: str, phi_h_deg, phi_g_deg, phases: list, bounds_deg, kinds) -> bytes:
    """Output (flexspline) rotation against generator angle over a turn, dwell phases shaded, the sectors where the
    major axis stands named between their boundaries, and the speed ratio of each phase (every move piece's u listed:
    the short pieces at the joints are too narrow to label)."""
    plt, fig, (ax, ax2) = _fig(2, (11, 7.5), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    for p in phases:
        if p["kind"] == "dwell":
            for a in (ax, ax2):
                a.axvspan(p["start_deg"], p["end_deg"], color="tab:green", alpha=0.12, lw=0)
    ax.plot(phi_h_deg, phi_g_deg, color="tab:blue", lw=1.5)
    for p in phases:
        if p["kind"] == "dwell":
            ax.text(
                0.5 * (p["start_deg"] + p["end_deg"]),
                0.02,
                f"dwell\n{p['length_deg']:.2f} deg",
                transform=ax.get_xaxis_transform(),
                ha="center",
                fontsize=8,
                color="tab:green",
            )
    ax.set_ylabel("output (flexspline) rotation phi_g, deg")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10, pad=16)
    _shade_sectors(ax, np.asarray(bounds_deg), kinds, phi_h_deg[0], phi_h_deg[-1], shade=False)
    pieces, longest = {}, None
    for p in phases:
        r = p["ratio"]
        y = 0.0 if r is None else 1.0 / r
        ax2.plot([p["start_deg"], p["end_deg"]], [y, y], color="tab:red" if r is not None else "tab:green", lw=2.5)
        if r is not None and p["length_deg"] > 20:
            ax2.text(0.5 * (p["start_deg"] + p["end_deg"]), y, f"u = {r:.4g}", ha="center", va="bottom", fontsize=8)
        if r is not None:
            pieces.setdefault(round(r, 6), p["length_deg"])
            if longest is None or p["length_deg"] > longest["length_deg"]:
                longest = p
    if pieces:
        text = "move pieces (red), major axis over:\n" + "\n".join(
            f"u = {r:.4g}: {length:.2f} deg" for r, length in sorted(pieces.items(), key=lambda kv: kv[1])
        )
        ax2.text(  # above the longest move piece, clear of the lines
            0.5 * (longest["start_deg"] + longest["end_deg"]),
            0.95,
            text,
            transform=ax2.get_xaxis_transform(),
            ha="center",
            va="top",
            fontsize=7,
            bbox=dict(boxstyle="round", fc="white", ec="0.7", alpha=0.9),
        )
    ax2.set_ylabel("d phi_g / d phi_h (1/u)")
    ax2.set_xlabel("generator angle phi_h = the major axis's angle on the rigid gear, deg (rigid gear fixed)")
    ax2.grid(alpha=0.3)
    for k, b in enumerate(bounds_deg):
        for a in (ax, ax2):
            a.axvline(b, color="0.6", lw=0.6, ls="--", label="sector boundary" if (a is ax and k == 0) else None)
    ax.legend(fontsize=8, loc="upper right")
    ax2.set_xlim(phi_h_deg[0], phi_h_deg[-1])
    fig.tight_layout()
    return _png(plt, fig)


def audit_png(title: str, centres_deg, bounds_deg, kinds, curves: dict, tol_um: float, tip_curves=None) -> bytes:
    """Smallest clearance of every rigid tooth to any flexspline tooth over the whole cycle, for several height sets;
    below ``tol_um`` (minus the interference tolerance) in red: interference. ``tip_curves`` (same keys): each
    tooth's smallest clearance where a flexspline tip faces its tip, in a second panel, at or below ``-tol_um``
    (the contact tolerance) a tip-to-tip jam: the margin [S5]'s heights are for."""
    n = 1 if tip_curves is None else 2
    plt, fig, axs = _fig(n, (11, 5 if n == 1 else 8), sharex=True, squeeze=False)
    c = np.asarray(centres_deg)
    markers = ["o", "s", "^", "d"]
    panels = [
        (axs[0, 0], curves, tol_um, "smallest clearance to a flexspline tooth\nover the cycle, um", "interference")
    ]
    if tip_curves is not None:
        panels.append(
            (axs[1, 0], tip_curves, -tol_um, "smallest clearance, tip facing tip,\nover the cycle, um", "tip-to-tip")
        )
    for ax, cur, limit, ylabel, what in panels:
        _shade_sectors(ax, np.asarray(bounds_deg), kinds, bounds_deg[0], bounds_deg[-1])
        for (name, vals), mk in zip(cur.items(), markers):
            v = np.asarray(vals, dtype=float)
            ok = np.isfinite(v)
            low = f": smallest {v[ok].min():+.2f} um" if ok.any() else ": never"
            ax.plot(c[ok], v[ok], mk, ms=6 if mk == "o" else 4, mfc="none" if mk == "o" else None, label=name + low)
            bad = ok & (v <= limit)
            ax.plot(c[bad], v[bad], mk, ms=9, mfc="none", mec="red")
        ax.axhline(limit, color="red", lw=0.8, ls="--", label=f"{limit:+g} um: at or below = {what} (red rings)")
        ax.set_ylabel(ylabel, fontsize=9)
        ax.grid(alpha=0.3)
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.45 * (hi - lo))  # headroom: the legend over no tooth
        ax.legend(fontsize=8, loc="upper right", ncol=3)
    axs[0, 0].set_title(title, fontsize=10, pad=16)
    axs[-1, 0].set_xlabel("rigid tooth centre angle, deg")
    fig.tight_layout()
    return _png(plt, fig)
