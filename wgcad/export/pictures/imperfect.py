"""Pictures of an imperfect drive's audit: the entry gap of every passage of a tooth through the entry (docs/models.md 6.2, 7)."""

from __future__ import annotations

import numpy as np

from .drive import DPI, MIN_FONT_PT, legend_outside
from .mpl import png_bytes, pyplot

__all__ = ["entry_passages_figure", "entry_passages_png"]


def entry_passages_png(phi_h_deg, gap_um, section, sections_z, perfect_um, tol_um: float, title: str) -> bytes:
    """:func:`entry_passages_figure` as PNG bytes."""
    return png_bytes(entry_passages_figure(phi_h_deg, gap_um, section, sections_z, perfect_um, tol_um, title))


def entry_passages_figure(phi_h_deg, gap_um, section, sections_z, perfect_um, tol_um: float, title: str):
    """Entry gap of every passage against the generator angle at its crossing, one colour per section.

    ``phi_h_deg``, ``gap_um``, ``section`` (P,): each passage's generator
    angle, gap (polygon figure) and section index; ``sections_z`` the
    sections' z (mm, None without coning); ``perfect_um`` the perfect
    drive's entry gap per section (a dashed line each).
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(14, 5.6), layout="constrained", dpi=DPI)
    ph, g, si = np.asarray(phi_h_deg, float), np.asarray(gap_um, float), np.asarray(section, int)
    for s, z in enumerate(sections_z):
        sel = si == s
        lab = "no coning" if z is None else f"z = {z:g} mm"
        if sel.any():
            ax.plot(
                ph[sel],
                g[sel],
                ".",
                ms=3.5,
                color=f"C{s}",
                label=f"{lab}: {int(sel.sum())} passages, {g[sel].min():.2f} to {g[sel].max():.2f} um",
            )
        if s < len(perfect_um) and np.isfinite(perfect_um[s]):
            ax.axhline(
                perfect_um[s], color=f"C{s}", ls="--", lw=1.0, label=f"{lab}: perfect parts {perfect_um[s]:.2f} um"
            )
    fin = g[np.isfinite(g)]
    if fin.size and fin.min() < tol_um:
        ax.axhspan(
            min(fin.min(), -tol_um), tol_um, color="0.88", zorder=0, label=f"closed (below the {tol_um:g} um tolerance)"
        )
    ax.set_xlabel("generator angle at the crossing, deg", fontsize=10)
    ax.set_ylabel("entry gap, um (polygon figures)", fontsize=10)
    ax.tick_params(labelsize=max(9, MIN_FONT_PT))
    ax.grid(alpha=0.3)
    legend_outside(ax)  # beside the axes: it cannot cover a passage
    ax.set_title(title, fontsize=10)
    return fig
