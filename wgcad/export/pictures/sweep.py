"""PNG figures of a sweep: distributions against the limits, yield with its interval, parameters driving failures, response surfaces of grids."""

from __future__ import annotations

import math

import numpy as np

from ...sweep.summary import MIN_FAILING_TO_RANK, failing_samples, few_failing_note, passes, weakest_figure
from .mpl import png_bytes
from .mpl import pyplot as _plt

__all__ = ["sweep_pngs", "histograms_png", "sensitivity_png", "surface_png"]


def _png(fig, plt) -> bytes:
    return png_bytes(fig, tight_layout=True)


def _limit_lines(ax, lim, vertical=True):
    if lim is None:
        return
    for v, lab in ((lim[0], "min"), (lim[1], "max")):
        if v is not None:
            (ax.axvline if vertical else ax.axhline)(v, color="tab:red", ls="--", lw=1.2, label=f"limit {lab} {v:g}")


def _constant(ax, value: float, n: int, lo: float, hi: float) -> None:
    """A figure every sample has the same value of: one line at it and the words, not a histogram bar."""
    if hi == lo:
        lo, hi = value - 0.5 * max(abs(value), 1.0), value + 0.5 * max(abs(value), 1.0)
    ax.set_xlim(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
    ax.vlines([value], 0, n, color="0.45", lw=3)
    ax.text(0.5, 0.6, f"constant: all {n} samples {value:g}", transform=ax.transAxes, ha="center", fontsize=10)
    ax.set_ylim(0, 1.15 * n)


def histograms_png(spec, cols: dict, summ: dict) -> bytes:
    """One histogram per recorded figure (computed samples), limits dashed, the share within them in the title; the yield in the heading."""
    plt = _plt()
    from matplotlib.ticker import MaxNLocator

    figs = list(spec.record)
    n = len(figs)
    ncol = min(3, n)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.9 * nrow + 0.6), dpi=90, squeeze=False)
    ok = cols["status"] == "ok"
    for k, f in enumerate(figs):
        ax = axes[k // ncol][k % ncol]
        v = cols[f][ok]
        v = v[np.isfinite(v)]
        lim = spec.limits.get(f)
        if v.size:
            lo, hi = float(v.min()), float(v.max())
            if lim is not None:  # the limit in view even when every sample is far from it
                lo = min(lo, *(x for x in lim if x is not None))
                hi = max(hi, *(x for x in lim if x is not None))
            if float(v.min()) == float(v.max()):
                # one value: a bar of made-up width would read as a spread; say it
                _constant(ax, float(v[0]), v.size, lo, hi)
            else:
                ax.hist(
                    v,
                    bins=min(60, max(10, int(np.sqrt(v.size)))),
                    range=(lo, hi),
                    color="0.45",
                    edgecolor="white",
                    lw=0.3,
                )
        _limit_lines(ax, lim)
        title = f + (" (constant)" if v.size and float(v.min()) == float(v.max()) else "")
        if lim is not None and summ["limits"].get(f, {}).get("fraction") is not None:
            title += f": {100 * summ['limits'][f]['fraction']:.1f} % within"
        nan = int((~np.isfinite(cols[f][ok])).sum())
        ax.set_title(title + (f" ({nan} without a value)" if nan else ""), fontsize=9)
        ax.set_xlabel(f)
        ax.set_ylabel("samples")
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(alpha=0.3)
        if lim is not None:
            ax.legend(fontsize=7, loc="upper right")
    for k in range(n, nrow * ncol):
        axes[k // ncol][k % ncol].axis("off")
    c = summ["counts"]
    head = f"{summ['name']}: {c['ok']} samples computed of {c['total']}"
    if c["refused"] or c["failed"] or c["error"]:
        head += f" ({c['refused']} refused, {c['failed']} failed, {c['error']} errors: not shown)"
    y = summ.get("yield")
    if y and y["of"]:
        head += f"\nyield {100 * y['fraction']:.2f} %, {100 * summ['confidence']:.0f} % interval {100 * y['ci'][0]:.2f} .. {100 * y['ci'][1]:.2f} % (Clopper-Pearson)"
    fig.suptitle(head, fontsize=10)
    return _png(fig, plt)


def sensitivity_png(spec, cols: dict, summ: dict) -> bytes:
    """Left: random parameters ranked by their rank correlation with failing (or with the first figure); right: the leading parameter against the figure that fails most, failing samples in red."""
    plt = _plt()
    rows = summ["sensitivity"]
    ok = cols["status"] == "ok"
    has_fail = any(r["failure"] is not None for r in rows)
    # one or two failing samples decide a ranking by failing: below the least, ranked by the figure's own margin
    few = has_fail and failing_samples(summ) < MIN_FAILING_TO_RANK
    by_fail = has_fail and not few
    fig_name = weakest_figure(summ) if summ["limits"] else next(iter(spec.record))
    if few:
        rows = sorted(rows, key=lambda r: -abs(r["figures"].get(fig_name) or 0.0))

    def score(r):
        v = r["failure"] if by_fail else r["figures"].get(fig_name)
        return 0.0 if v is None else v

    fig, ax = plt.subplots(1, 2, figsize=(13, 0.5 * len(rows) + 3.2), dpi=90, gridspec_kw={"width_ratios": [1, 1.2]})
    names = [r["parameter"] + (" (phase: |circular r|)" if r["phase"] else "") for r in rows]
    yy = np.arange(len(rows))[::-1].astype(float)
    # with few failures the rank correlation with failing is weak and noisy: the correlation with the
    # figure itself (the margin to its limit) is shown beside it
    fig_vals = [(r["figures"].get(fig_name) or 0.0) for r in rows]
    if by_fail:
        ax[0].barh(yy + 0.2, [score(r) for r in rows], height=0.38, color="tab:red", label="with failing")
        ax[0].barh(yy - 0.2, fig_vals, height=0.38, color="0.55", label=f"with {fig_name}")
        ax[0].legend(fontsize=8, loc="lower right")
    else:
        ax[0].barh(yy, fig_vals, color="0.55")
    ax[0].set_yticks(yy, names, fontsize=8)
    ax[0].axvline(0, color="k", lw=0.6)
    ax[0].set_xlim(-1, 1)
    ax[0].set_xlabel("rank correlation (phases: circular, 0..1)")
    title = "parameters driving failures" if by_fail else "parameters driving " + fig_name
    if few:
        title += "\nfailures not ranked: " + few_failing_note(summ)
    ax[0].set_title(title, fontsize=10)
    ax[0].grid(alpha=0.3, axis="x")
    if rows:
        p = next(q for q in spec.parameters if q.name == rows[0]["parameter"])
        x = np.asarray(cols[p.name][ok], float)
        y = cols[fig_name][ok]
        shown = ""
        if len(x) > 20000:  # a scatter of a million points is a blot: an even subsample (every k-th sample)
            k = -(-len(x) // 20000)
            shown = f" (every {k}th of {len(x)} samples)"
            x, y = x[::k], y[::k]
        if spec.limits:
            good = passes(cols, spec.limits)[ok]
            if shown:
                good = good[::k]
            ax[1].scatter(x[good], y[good], s=5, color="0.4", label="within the limits", rasterized=True)
            ax[1].scatter(x[~good], y[~good], s=7, color="tab:red", label="outside", rasterized=True)
        else:
            ax[1].scatter(x, y, s=5, color="0.4", rasterized=True)
        _limit_lines(ax[1], spec.limits.get(fig_name), vertical=False)
        ax[1].set_xlabel(p.name)
        ax[1].set_ylabel(fig_name)
        ax[1].set_title(f"{fig_name} against the leading parameter{shown}", fontsize=10)
        ax[1].grid(alpha=0.3)
        ax[1].legend(fontsize=8, loc="best")
    return _png(fig, plt)


def _limit_contours(ax, m, lim) -> None:
    """A map's limits as dashed red contours (interpolated between the grid points), each named in a legend."""
    from matplotlib.lines import Line2D

    if lim is None or np.isfinite(m).sum() < 4 or m.shape[0] < 2 or m.shape[1] < 2:
        return
    drawn = []
    for v, lab in zip(lim, ("min", "max")):
        if v is not None and np.nanmin(m) < v < np.nanmax(m):
            ax.contour(m.T, levels=[v], colors="tab:red", linestyles="--")
            drawn.append(Line2D([], [], color="tab:red", ls="--", label=f"limit {lab} {v:g} (interpolated)"))
    if drawn:
        ax.legend(handles=drawn, fontsize=7, loc="upper left", framealpha=0.9)


def surface_png(spec, summ: dict) -> bytes:
    """Response of each figure over the grid: a line with the range over the random draws (one grid parameter) or a map (two; further ones averaged)."""
    plt = _plt()
    g = summ["grid"]
    figs = list(spec.record)
    n = len(figs) + (1 if g["yield"] else 0)
    ncol = min(3, n)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.4 * ncol, 4.2 * nrow + 0.4), dpi=90, squeeze=False)
    shape = tuple(g["shape"])
    names, values = g["parameters"], g["values"]
    text_axis = [any(isinstance(v, str) for v in vs) for vs in values]
    items = [
        (
            f,
            np.asarray(g["surfaces"][f]["mean"], float),
            np.asarray(g["surfaces"][f]["min"], float),
            np.asarray(g["surfaces"][f]["max"], float),
        )
        for f in figs
    ]
    if g["yield"]:
        yv = np.asarray([np.nan if y["fraction"] is None else 100 * y["fraction"] for y in g["yield"]], float).reshape(
            shape
        )
        # one draw per point (a design study): a point meets the limits or not, no yield to speak of
        items.append(("meets the limits (100: yes)" if summ.get("kind") == "grid" else "yield %", yv, yv, yv))
    for k, (f, mean, lo, hi) in enumerate(items):
        ax = axes[k // ncol][k % ncol]
        if len(shape) == 1:
            xs = np.arange(shape[0]) if text_axis[0] else np.asarray(values[0], float)
            if f == "yield %" or f.startswith("meets the limits"):
                ci = np.asarray([y["ci"] for y in g["yield"]], float) * 100.0
                ax.errorbar(
                    xs,
                    mean,
                    yerr=[mean - ci[:, 0], ci[:, 1] - mean],
                    fmt="o-",
                    color="k",
                    capsize=3,
                    label=f"yield, {100 * summ['confidence']:.0f} % interval",
                )
                ax.set_ylim(-3, 103)
            else:
                ax.plot(xs, mean, "o-", color="k", label="mean over the draws")
            if f == items[-1][0] and g["yield"]:
                pass
            elif np.any(hi > lo):
                ax.fill_between(xs, lo, hi, color="0.8", label="range over the draws")
            if text_axis[0]:
                ax.set_xticks(xs, values[0], fontsize=8)
            ax.set_xlabel(names[0])
            ax.set_ylabel(f)
            _limit_lines(ax, spec.limits.get(f), vertical=False)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="best")
        else:
            m = mean.reshape(shape[0], shape[1], -1)
            with np.errstate(invalid="ignore"):
                m = np.nanmean(m, axis=2) if m.shape[2] > 1 else m[:, :, 0]
            is_yield = f == "yield %" or f.startswith("meets the limits")
            im = ax.imshow(
                m.T,
                origin="lower",
                aspect="auto",
                cmap="RdYlGn" if is_yield else "viridis",
                vmin=0.0 if is_yield else None,
                vmax=100.0 if is_yield else None,
            )
            for i in range(m.shape[0]):
                for j in range(m.shape[1]):
                    if np.isfinite(m[i, j]):
                        ax.text(
                            i,
                            j,
                            f"{m[i, j]:.3g}",
                            ha="center",
                            va="center",
                            fontsize=7,
                            color="black" if is_yield or m[i, j] >= np.nanmean(m) else "white",
                        )
            ax.set_xticks(range(shape[0]), [str(v) for v in values[0]], fontsize=8)
            ax.set_yticks(range(shape[1]), [str(v) for v in values[1]], fontsize=8)
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
            fig.colorbar(im, ax=ax, label=f)
            _limit_contours(ax, m, spec.limits.get(f))
        extra = " (mean over the other grid parameters)" if len(shape) > 2 else ""
        ax.set_title(f + extra, fontsize=9)
    for k in range(len(items), nrow * ncol):
        axes[k // ncol][k % ncol].axis("off")
    fig.suptitle(f"{summ['name']}: response over the grid", fontsize=10)
    return _png(fig, plt)


def sweep_pngs(spec, cols: dict, summ: dict) -> dict:
    """``{file name: PNG bytes}``: histograms, and sensitivity (random parameters) and surfaces (grids) where they apply."""
    # a grid of designs is a table and a surface, not a distribution: no histograms of it
    out = {} if summ.get("kind") == "grid" else {"sweep_histograms.png": histograms_png(spec, cols, summ)}
    if summ["sensitivity"]:
        out["sweep_sensitivity.png"] = sensitivity_png(spec, cols, summ)
    if summ["grid"] is not None:
        out["sweep_surface.png"] = surface_png(spec, summ)
    return out
