"""``wgcad sweep --html``: a sweep as one interactive page: counts and yield, each recorded figure's distribution (Monte Carlo) or its values over the grid (design study), the parameters that drive failures."""

from __future__ import annotations

import itertools

import numpy as np

from ...extras import require
from ...sweep.summary import MIN_FAILING_TO_RANK, failing_samples, few_failing_note, weakest_figure
from .frame import figure, fmt, page, table

__all__ = ["sweep_html"]


def _histograms(go, spec, cols, summ):
    from plotly.subplots import make_subplots

    figs = list(spec.record)
    ncol = min(3, len(figs))
    nrow = -(-len(figs) // ncol)
    ok = cols["status"] == "ok"
    vals = {f: cols[f][ok][np.isfinite(cols[f][ok])] for f in figs}
    const = {f: v.size > 0 and float(v.min()) == float(v.max()) for f, v in vals.items()}
    titles = [f"{f} (constant: all {vals[f].size} samples {vals[f][0]:g})" if const[f] else f for f in figs]
    fig = make_subplots(rows=nrow, cols=ncol, subplot_titles=titles)
    for k, f in enumerate(figs):
        r, c = k // ncol + 1, k % ncol + 1
        v = vals[f]
        if const[f]:
            # one value: a histogram bar of made-up width would read as a spread
            fig.add_trace(
                go.Scatter(
                    x=[v[0], v[0]], y=[0, v.size], mode="lines", line=dict(color="#666", width=3), showlegend=False
                ),
                row=r,
                col=c,
            )
        else:
            fig.add_trace(go.Histogram(x=v, name=f, showlegend=False, marker_color="#666"), row=r, col=c)
        for x in spec.limits.get(f) or ():
            if x is not None:
                fig.add_vline(x=x, line_dash="dash", line_color="red", row=r, col=c)
    fig.update_layout(
        height=360 * nrow,
        template="plotly_white",
        title="each recorded figure over the computed samples (limits dashed)",
    )
    return fig


def _grid_rows(spec, summ):
    """One row per grid point: the parameters' values, each figure's mean, and whether it meets the limits."""
    g = summ["grid"]
    shape = tuple(g["shape"])
    rows = []
    for flat, idx in enumerate(itertools.product(*(range(n) for n in shape))):
        vals = [
            fmt(g["values"][j][i], 4) if not isinstance(g["values"][j][i], str) else fmt(g["values"][j][i])
            for j, i in enumerate(idx)
        ]
        means = []
        for f in spec.record:
            m = np.asarray(g["surfaces"][f]["mean"], float).reshape(-1)[flat]
            means.append(fmt(float(m), 3))
        y = g["yield"][flat] if g["yield"] else None
        verdict = "-" if y is None or y["fraction"] is None else f"{100 * y['fraction']:.0f} %"
        rows.append((str(flat), *vals, *means, verdict))
    head = ["point", *g["parameters"], *list(spec.record), "meets the limits"]
    return table(rows, head=head)


def _surface(go, spec, summ):
    g = summ["grid"]
    shape = tuple(g["shape"])
    fig = go.Figure()
    if len(shape) == 1:
        x = g["values"][0]
        for f in spec.record:
            fig.add_trace(go.Scatter(x=x, y=g["surfaces"][f]["mean"], mode="lines+markers", name=f))
        fig.update_xaxes(title=g["parameters"][0])
    else:
        f = next(iter(spec.record))
        mean = np.asarray(g["surfaces"][f]["mean"], float)
        while mean.ndim > 2:
            mean = np.nanmean(mean, axis=-1)
        fig.add_trace(
            go.Heatmap(
                z=mean.T, x=[str(v) for v in g["values"][0]], y=[str(v) for v in g["values"][1]], colorbar=dict(title=f)
            )
        )
        fig.update_xaxes(title=g["parameters"][0])
        fig.update_yaxes(title=g["parameters"][1])
    fig.update_layout(
        height=520, template="plotly_white", title="the figures over the grid (means over any random draws)"
    )
    return fig


def _sensitivity(go, summ):
    rows = summ["sensitivity"]
    few = any(r["failure"] is not None for r in rows) and failing_samples(summ) < MIN_FAILING_TO_RANK
    title = "random parameters ranked by their rank correlation with failing (or with the first figure)"
    if few:
        # one or two failing samples decide a ranking by failing: ranked by the weakest figure's margin instead
        f = weakest_figure(summ)
        rows = sorted(rows, key=lambda r: -abs(r["figures"].get(f) or 0.0))
        vals = [r["figures"].get(f) or 0.0 for r in rows[:12]]
        title = f"random parameters ranked by their rank correlation with {f}<br><sub>failures not ranked: {few_failing_note(summ)}</sub>"
    else:
        vals = [
            r["failure"]
            if r["failure"] is not None
            else max((v or 0.0 for v in r["figures"].values()), key=abs, default=0.0)
            for r in rows[:12]
        ]
    rows = rows[:12]
    names = [r["parameter"] for r in rows]
    fig = go.Figure(go.Bar(x=vals[::-1], y=names[::-1], orientation="h"))
    fig.update_layout(height=140 + 30 * len(rows), template="plotly_white", title=title)
    fig.update_xaxes(title="rank correlation")
    return fig


def sweep_html(spec, cols: dict, summ: dict) -> str:
    """The page of a sweep's summary (:func:`wgcad.sweep.summary.summarize`) and its columns."""
    require("html")  # plotly draws the page
    import plotly.graph_objects as go

    c = summ["counts"]
    head = [
        f"<p>{c['ok']} samples computed of {c['total']} ({c['refused']} refused, {c['failed']} failed, {c['error']} errors); "
        f"design {fmt(summ['design'])}, seed {fmt(summ['seed'])}.</p>"
    ]
    y = summ.get("yield")
    if y and y["of"] and summ.get("kind") != "grid":
        head.append(
            f"<p><b>yield {100 * y['fraction']:.2f} %</b> ({y['pass']} of {y['of']}), {100 * summ['confidence']:.0f} % interval "
            f"{100 * y['ci'][0]:.2f} .. {100 * y['ci'][1]:.2f} % ({y['method']})</p>"
        )
    stats = summ["figures"]
    head.append(
        table(
            [
                (
                    f,
                    fmt(s.get("mean"), 4),
                    fmt(s.get("sd"), 4),
                    fmt(s.get("p01"), 4),
                    fmt(s.get("median"), 4),
                    fmt(s.get("p99"), 4),
                    fmt((summ["limits"].get(f) or {}).get("fraction"), 4),
                )
                for f, s in stats.items()
            ],
            head=["figure", "mean", "sd", "1 %", "median", "99 %", "share within the limits"],
        )
        if summ.get("kind") != "grid"
        else _grid_rows(spec, summ)
    )
    figs = []
    if summ.get("kind") != "grid":
        figs.append(("Distributions", figure(_histograms(go, spec, cols, summ), "histograms")))
    if summ["grid"] is not None:
        figs.append(("Over the grid", figure(_surface(go, spec, summ), "surface")))
    if summ["sensitivity"]:
        figs.append(("What drives it", figure(_sensitivity(go, summ), "sensitivity")))
    return page(f"{summ['name']}: sweep", "sweep", head, figs)
