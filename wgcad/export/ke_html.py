"""``wgcad ke --html``: the kinematic error as one interactive page: KE over the revolution, its spectrum with the expected orders, the KE under load and the installation scan where computed (docs/models.md 6.2, 6.3)."""

from __future__ import annotations

import numpy as np

from wgcad.units import ARCSEC_PER_RAD

from .html_page import figure, fmt, page, table

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
        height=520,
        template="plotly_white",
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
    fig.update_layout(
        title=f"spectrum up to order {top:g} (per flexspline revolution; four decades below the strongest)",
        height=480,
        template="plotly_white",
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
    """The page of a :class:`~wgcad.report.ke_run.KERun`."""
    import plotly.graph_objects as go

    doc = run.doc
    name = run.drive.design.drive.name
    rows = [
        ("largest KE, peak to peak", f"{fmt(doc['ke_pp_arcsec'], 2)} arcsec", f"engagement: {fmt(doc['engagement'])}"),
        ("perfect parts", f"{fmt(doc['intrinsic_ke_pp_arcsec'], 3)} arcsec", "the mesh's own ripple"),
        (
            "lost motion",
            f"{fmt(doc['lost_motion_arcsec']['min'], 1)} .. {fmt(doc['lost_motion_arcsec']['max'], 1)} arcsec",
            "over the revolution",
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
    top = table(
        [(f"{s['order']:g}", f"{s['amplitude_arcsec']:.3f}") for s in doc["spectrum_top"]],
        head=["order", "amplitude, arcsec"],
    )
    head = [table(rows), "<p>strongest orders:</p>", top]
    figs = [("Kinematic error", figure(_ke(go, run), "ke")), ("Spectrum", figure(_spectrum(go, run), "spectrum"))]
    if run.scan is not None:
        figs.append(("Installation angle", figure(_install(go, run), "install")))
    return page(f"{name}: kinematic error", "ke", head, figs)
