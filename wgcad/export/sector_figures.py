"""Pictures of a discrete-motion drive: tooth heights both ways, the motion law, the sectored audit (PNG bytes; matplotlib inside the functions)."""

from __future__ import annotations

import numpy as np

from .mpl import png_bytes, pyplot

__all__ = ["heights_png", "motion_png", "audit_png"]


def _fig(nrows, figsize, **kw):
    plt = pyplot()
    fig, axs = plt.subplots(nrows, 1, figsize=figsize, dpi=100, **kw)
    return plt, fig, axs


def _png(plt, fig) -> bytes:
    return png_bytes(fig)


def _shade_sectors(ax, bounds_deg, kinds, lo, hi):
    for a, b, k in zip(bounds_deg[:-1], bounds_deg[1:], kinds):
        if hi <= a or lo >= b:
            continue
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


def heights_png(
    title: str,
    centres_deg,
    bounds_deg,
    kinds,
    full_mm: float,
    closed_mm,
    simulated_mm,
    built_mm,
    boundary_mm=None,
    tip_clearance_um: float = 0.0,
) -> bytes:
    """Tooth heights over half the gear (one wave: a coupling and a transmission sector): closed form, simulated, built; and their difference."""
    plt, fig, (ax, ax2) = _fig(2, (11, 7.5), sharex=True, gridspec_kw={"height_ratios": [2.2, 1]})
    c = np.asarray(centres_deg)
    lo, hi = bounds_deg[0], bounds_deg[0] + 180.0
    sel = (c >= lo) & (c < hi)
    _shade_sectors(ax, np.asarray(bounds_deg), kinds, lo, hi)
    ax.axhline(1e3 * full_mm, color="0.5", lw=1, ls=":", label=f"full height {1e3 * full_mm:.1f} um")
    if boundary_mm is not None:
        ax.plot(
            c[sel],
            1e3 * np.asarray(boundary_mm)[sel],
            "^-",
            color="tab:gray",
            ms=4,
            lw=1,
            label="closed form, axis on the sector boundary (patent reading)",
        )
    ax.plot(
        c[sel],
        1e3 * np.asarray(closed_mm)[sel],
        "o-",
        color="tab:blue",
        ms=4,
        lw=1.2,
        label="closed form (theory 2.3), out-of-register angle",
    )
    ax.plot(
        c[sel],
        1e3 * np.asarray(simulated_mm)[sel],
        "s-",
        color="tab:red",
        ms=3.5,
        lw=1.2,
        label=f"simulated: largest keeping {tip_clearance_um:g} um tip clearance",
    )
    ax.plot(c[sel], 1e3 * np.asarray(built_mm)[sel], "x", color="k", ms=7, label="built")
    ax.set_ylabel("tooth height h_i, um (root to tip)")
    ax.set_ylim(0, 1e3 * full_mm * 1.12)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10, pad=16)
    d = 1e3 * (np.asarray(simulated_mm) - np.asarray(closed_mm))
    _shade_sectors(ax2, np.asarray(bounds_deg), kinds, lo, hi)
    ax2.plot(c[sel], d[sel], "d-", color="tab:purple", ms=4, lw=1)
    ax2.axhline(0.0, color="0.4", lw=0.8)
    ax2.set_ylabel("simulated - closed form, um")
    ax2.set_xlabel("tooth centre angle on the rigid gear, deg (counter-clockwise; the other half is the same)")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return _png(plt, fig)


def motion_png(title: str, phi_h_deg, phi_g_deg, phases: list, bounds_deg, kinds) -> bytes:
    """Output (flexspline) rotation against generator angle over a turn, dwell phases shaded, and the speed ratio of each phase."""
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
    ax.set_title(title, fontsize=10)
    for p in phases:
        r = p["ratio"]
        y = 0.0 if r is None else 1.0 / r
        ax2.plot([p["start_deg"], p["end_deg"]], [y, y], color="tab:red" if r is not None else "tab:green", lw=2.5)
        if r is not None and p["length_deg"] > 20:
            ax2.text(0.5 * (p["start_deg"] + p["end_deg"]), y, f"u = {r:.4g}", ha="center", va="bottom", fontsize=8)
    ax2.set_ylabel("d phi_g / d phi_h (1/u)")
    ax2.set_xlabel("generator angle phi_h, deg (rigid gear fixed)")
    ax2.grid(alpha=0.3)
    for b in bounds_deg:
        for a in (ax, ax2):
            a.axvline(b, color="0.6", lw=0.6, ls="--")
    ax2.set_xlim(phi_h_deg[0], phi_h_deg[-1])
    fig.tight_layout()
    return _png(plt, fig)


def audit_png(title: str, centres_deg, bounds_deg, kinds, curves: dict, tol_um: float) -> bytes:
    """Smallest clearance to a facing flexspline tip, per rigid tooth, over the whole cycle, for several height sets; tip-to-tip in red."""
    plt, fig, ax = _fig(1, (11, 5))
    c = np.asarray(centres_deg)
    _shade_sectors(ax, np.asarray(bounds_deg), kinds, bounds_deg[0], bounds_deg[-1])
    markers = ["o", "s", "^", "d"]
    for (name, vals), mk in zip(curves.items(), markers):
        v = np.asarray(vals, dtype=float)
        ok = np.isfinite(v)
        ax.plot(c[ok], v[ok], mk, ms=4, label=name)
        bad = ok & (v <= tol_um)
        ax.plot(c[bad], v[bad], mk, ms=7, mfc="none", mec="red")
    ax.axhline(
        tol_um,
        color="red",
        lw=0.8,
        ls="--",
        label=f"contact tolerance {tol_um:g} um: at or below = tip-to-tip (red rings)",
    )
    ax.set_xlabel("rigid tooth centre angle, deg")
    ax.set_ylabel("min clearance to a facing flexspline tip, um")
    ax.set_title(title, fontsize=10, pad=16)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _png(plt, fig)
