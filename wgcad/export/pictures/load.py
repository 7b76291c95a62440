"""PNG pictures of the loaded drive: entry gap against torque, and the force distribution around the rim (docs/models.md 4.1, 5)."""

from __future__ import annotations

import numpy as np

from .mpl import png_bytes, pyplot

__all__ = ["entry_gap_png", "force_distribution_png"]


def _fig(w=9.0, h=5.0):
    plt = pyplot()
    return plt, plt.figure(figsize=(w, h), dpi=110)


def _png(plt, fig) -> bytes:
    return png_bytes(fig, bbox_inches="tight", metadata={"Software": None})


def entry_gap_png(series: list, title: str, tol_um: float = 1.0) -> bytes:
    """Entry gap against output torque, one line per series.

    Parameters
    ----------
    series : list of dict
        ``label``, ``torque_nm`` (L,), ``entry_gap_um`` (L,) (smallest over waves and sections),
        optional ``stiffness`` text for the legend.
    """
    plt, fig = _fig()
    ax = fig.add_subplot(111)
    styles = ["-o", "--s", "-^", "--v", "-d", "--x"]
    for k, s in enumerate(series):
        g = np.array([np.nan if v is None else v for v in s["entry_gap_um"]], dtype=float)
        ax.plot(s["torque_nm"], g, styles[k % len(styles)], ms=4, label=s["label"])
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhspan(-tol_um, tol_um, color="0.85", lw=0, label=f"contact tolerance +-{tol_um:g} um")
    vals = np.array([v for s in series for v in s["entry_gap_um"] if v is not None], dtype=float)
    log = vals.size and np.nanmax(np.abs(vals)) > 20.0 * max(np.nanmin(np.abs(vals)), 1.0)
    if log:  # series of very different size (e.g. involute ~5 um, cycloidal ~180 um): both readable
        ax.set_yscale("symlog", linthresh=10.0)
        # ticks where the values lie: the linear band |gap| < 10 um had none but 0, and the decades
        lo, hi = min(float(np.nanmin(vals)), -tol_um), float(np.nanmax(vals))
        ticks = [
            t for t in (-1000, -100, -50, -20, -10, -5, -2, 0, 2, 5, 10, 20, 50, 100, 200, 500, 1000) if lo <= t <= hi
        ]
        ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
    ax.set_xlabel("output torque M_c, N m")
    ax.set_ylabel(
        "entry gap Delta [S1], um\n(below 0: tips interfere" + ("; linear below 10 um, log above)" if log else ")")
    )
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return _png(plt, fig)


def force_distribution_png(levels: list, title: str) -> bytes:
    """Tooth force (sum over sections and flanks) against the tooth's angle from the major axis, one line per torque.

    Parameters
    ----------
    levels : list of dict
        :func:`wgcad.elastic.sweep.level_summary` results.
    """
    plt, fig = _fig(10.0, 6.0)
    ax = fig.add_subplot(211)
    ax2 = fig.add_subplot(212)
    cmap = plt.get_cmap("viridis")
    n = max(len(levels) - 1, 1)
    for k, lv in enumerate(levels):
        a = np.mod(np.array(lv["tooth_angle_deg"]) + 180.0, 360.0) - 180.0
        o = np.argsort(a)
        f = np.array(lv["tooth_force_n"])[o]
        ax.plot(a[o], f, color=cmap(k / n), lw=1.0, label=f"{lv['torque_nm']:g} N m")
        b = np.mod(np.array(lv["ball_angle_deg"]) + 180.0, 360.0) - 180.0
        ob = np.argsort(b)
        ax2.plot(b[ob], np.array(lv["ball_load_n"])[ob], "o-", color=cmap(k / n), ms=3, lw=0.8)
    ax.set_ylabel("tooth force, N")
    ax.set_xlim(-180, 180)
    ax.grid(True, alpha=0.3)
    # beside the panels, not over them: the legend covered the force spikes it is about
    ax.legend(fontsize=7, ncol=1, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, title="torque")
    ax.set_title(title, fontsize=10)
    ax2.set_xlim(-180, 180)
    ax2.set_xlabel("angle from the generator major axis, deg")
    ax2.set_ylabel("ball load, N")
    ax2.grid(True, alpha=0.3)
    return _png(plt, fig)
