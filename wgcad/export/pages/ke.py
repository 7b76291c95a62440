"""``wgcad ke --html``: the kinematic error as one interactive page: KE over the revolution, its spectrum with the expected orders, the KE under load and the installation scan where computed (docs/models.md 6.2, 6.3)."""

from __future__ import annotations

import numpy as np

from wgcad.units import ARCSEC_PER_RAD

from ...extras import require
from .frame import figure, fmt, notes, page, table

__all__ = ["ke_html"]

_AS = ARCSEC_PER_RAD


#: most points a curve is drawn with (SVG in any browser; WebGL would fall back to software in a headless one)
MAX_POINTS = 20000


def _envelope(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """At most :data:`MAX_POINTS` points keeping the smallest and largest value of every run of ``b`` samples (the
    peaks a KE is read by stay exact); ``b`` = 1 when the curve is short enough."""
    n = len(y)
    b = int(np.ceil(2 * n / MAX_POINTS))
    if b <= 1:
        return x, y, 1
    m = n // b
    blocks = y[: m * b].reshape(m, b)
    lo = np.argmin(blocks, axis=1) + b * np.arange(m)
    hi = np.argmax(blocks, axis=1) + b * np.arange(m)
    idx = np.unique(np.concatenate([lo, hi, np.arange(m * b, n)]))
    return x[idx], y[idx], b


#: the legends under the plots, in rows across the page's width: beside them, their long names took 40 % of it
BELOW = dict(orientation="h", yanchor="top", y=-0.18, xanchor="left", x=0.0)


def _ke(go, run):
    res, intr = run.res, run.intr
    fig = go.Figure()
    turns = np.abs(res.phi_h) / (2 * np.pi)
    tx, ty, b = _envelope(turns, res.ke * _AS)
    drawn = "" if b == 1 else f" (drawn: the least and greatest of every {b} angles)"
    fig.add_trace(
        go.Scatter(x=tx, y=ty, mode="lines", name=f"KE ({res.engagement}), {res.ke_pp * _AS:.2f}'' p-p{drawn}")
    )
    if intr is not None:
        fig.add_trace(
            go.Scatter(
                x=np.abs(intr.phi_h) / (2 * np.pi),
                y=intr.ke * _AS,
                mode="lines",
                name=f"perfect parts, {intr.ke_pp * _AS:.3f}'' p-p",
            )
        )
    for L in run.loaded:
        fig.add_trace(
            go.Scatter(
                x=np.abs(L.phi_h) / (2 * np.pi),
                y=L.ke * _AS,
                mode="markers",
                marker=dict(size=4),
                name=f"{L.torque_nm:g} N m (whole mesh periods), {L.ke_pp * _AS:.2f}'' p-p",
            )
        )
    fig.update_layout(
        title="kinematic error over one flexspline revolution (zoom in for the mesh ripple)",
        height=560,
        template="plotly_white",
        legend=BELOW,
    )
    fig.update_xaxes(title="generator turns")
    fig.update_yaxes(title="KE, arcsec")
    return fig


def _spectrum(go, run):
    low = {k: v for k, v in run.expected.items() if k != "mesh"}
    top = max(low.values()) * 1.6 if low else float(run.orders.max())
    sel = (run.orders > 0) & (run.orders <= top)
    fig = go.Figure()
    a = run.amp[sel] * _AS
    floor = 1e-4 * float(a.max()) if a.size else 1e-6
    fig.add_trace(go.Scatter(x=run.orders[sel], y=np.maximum(a, floor), mode="lines", name="amplitude"))
    # the expected orders as marked points on the curve (labels in the legend and on hover: neighbours such as
    # 100 and 101 would print over each other as text)
    for label, order in low.items():
        i = int(np.argmin(np.abs(run.orders - order)))
        fig.add_trace(
            go.Scatter(
                x=[order],
                y=[max(float(run.amp[i] * _AS), floor)],
                mode="markers",
                marker=dict(size=10, symbol="triangle-down"),
                name=f"{label}: order {order:g}",
            )
        )
    strongest = [(t["order"], t["amplitude_arcsec"]) for t in run.doc.get("spectrum_top", [])[:4]]
    shown = [(o, a) for o, a in strongest if 0 < o <= top]
    if shown:
        # the summary's strongest orders where they are (D2's 300 and 301, the second strongest, were unmarked)
        fig.add_trace(
            go.Scatter(
                x=[o for o, _ in shown],
                y=[max(a, floor) for _, a in shown],
                mode="markers",
                marker=dict(size=11, symbol="circle-open", line=dict(width=2), color="#2ca02c"),
                name="strongest: " + ", ".join(f"{o:g} ({a:.3g}'')" for o, a in shown),
            )
        )
    fig.update_layout(
        title=f"spectrum up to order {top:g} (per flexspline revolution; four decades below the strongest)",
        height=540,
        template="plotly_white",
        legend=BELOW,
    )
    fig.update_xaxes(title="order")
    fig.update_yaxes(title="amplitude, arcsec", type="log")
    return fig


def _install(go, run):
    s = run.scan
    fig = go.Figure()
    fig.add_trace(go.Scatter(x=s[0], y=s[1], mode="lines+markers", name="rigid gear's installation angle"))
    if s[4] is not None:
        fig.add_trace(go.Scatter(x=s[0], y=s[4], mode="lines", name="flexspline's position"))
    fig.add_trace(go.Scatter(x=[s[2]], y=[s[3]], mode="markers", marker=dict(size=12, symbol="star"), name="best"))
    fig.update_layout(title="largest KE against installation angle", height=460, template="plotly_white")
    fig.update_xaxes(title="installation angle, deg")
    fig.update_yaxes(title="KE peak to peak, arcsec")
    return fig


def ke_html(run) -> str:
    """The page of a :class:`~wgcad.services.ke.KERun`."""
    require("html")  # plotly draws the page
    import plotly.graph_objects as go

    doc = run.doc
    name = run.drive.design.drive.name
    rows = [
        ("largest KE, peak to peak", f"{fmt(doc['ke_pp_arcsec'], 2)} arcsec", f"engagement: {fmt(doc['engagement'])}"),
        ("perfect parts", f"{fmt(doc['intrinsic_ke_pp_arcsec'], 3)} arcsec", "the mesh's own ripple"),
        (
            "free play between the flanks",
            f"{fmt(doc['free_play_arcsec']['min'], 1)} .. {fmt(doc['free_play_arcsec']['max'], 1)} arcsec",
            "no load, over the revolution (negative: the teeth interfere)",
        ),
        (
            "angles",
            str(doc["samples"]),
            f"{doc['per_mesh_period']} per mesh period, {fmt(doc['generator_turns'], 3)} generator turns",
        ),
        ("chord tolerance", f"{fmt(doc['chord_tol_um'])} um", "outlines to the exact curves (docs/models.md 6.2)"),
    ]
    for L in run.loaded:
        rows.append(
            (f"KE at {L.torque_nm:g} N m", f"{L.ke_pp * _AS:.2f} arcsec", f"{len(L.ke)} states at whole mesh periods")
        )
        sz = L.single_zone
        rows.append(
            (
                f"zones at {L.torque_nm:g} N m",
                f"single-zone at {100 * sz.mean():.1f} % of the samples",
                f"KE {L.ke_range(sz) * _AS:.2f}'' within them, {L.ke_range(~sz) * _AS:.2f}'' within the two-zone ones",
            )
        )
    top = table(
        [(f"{s['order']:g}", f"{s['amplitude_arcsec']:.3f}") for s in doc["spectrum_top"]],
        head=["order", "amplitude, arcsec"],
    )
    head = [table(rows), notes(doc.get("validity_notes", ()), title="VALIDITY:"), "<p>strongest orders:</p>", top]
    figs = [("Kinematic error", figure(_ke(go, run), "ke")), ("Spectrum", figure(_spectrum(go, run), "spectrum"))]
    if run.loaded:
        figs.append(("Zones under load", figure(_zones(go, run), "zones")))
    if run.scan is not None:
        figs.append(("Installation angle", figure(_install(go, run), "install")))
    return page(f"{name}: kinematic error", "ke", head, figs)


def _zones(go, run):
    """The lesser engagement zone's share of the tooth torque at every loaded sample (docs/models.md 4.2)."""
    from wgcad.accuracy.ke_load import SINGLE_ZONE_SHARE

    fig = go.Figure()
    for L in run.loaded:
        t = np.abs(L.phi_h) / (2 * np.pi)
        order = np.argsort(t)
        fig.add_trace(
            go.Scatter(
                x=t[order],
                y=100 * np.nanmin(L.zone_share, axis=1)[order],
                mode="markers",
                marker=dict(size=4),
                name=f"{L.torque_nm:g} N m",
            )
        )
    fig.add_hline(y=100 * SINGLE_ZONE_SHARE, line_dash="dash", annotation_text="single-zone below")
    fig.update_layout(
        title="the lesser zone's share of the tooth torque (single-zone engagement below the line)",
        height=420,
        template="plotly_white",
    )
    fig.update_xaxes(title="generator turns")
    fig.update_yaxes(title="share, %", range=[0, 52])
    return fig
