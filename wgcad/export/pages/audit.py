"""The audit as one self-contained, interactive page: zoomable figures (plotly, its script embedded) and the tables.

``wgcad audit --html PATH`` writes it. Nothing is fetched when the page is
viewed (plotly.js is inlined once, about 4.8 MB): it opens from a disk, a
mail or an archive. The figures are those of the PNGs
(:func:`wgcad.export.pictures.audit.audit_plot_data`, computed once for
both) plus the whole drive at the tightest spot's generator angle, from
which a designer zooms down to the tooth pair and its microns.
"""

from __future__ import annotations

import html

import numpy as np

from ...extras import require
from ...placement.deformed import deformed_state
from ..pictures.drive import VS_ANGLE_MIN_PAD_UM, profile_y_range
from .frame import figure as _figure
from .frame import fmt as _fmt
from .frame import notes as _notes
from .frame import page

__all__ = ["audit_html", "audit_figures", "vs_angle_y_range"]


def _lines(go, fig, polys, name, color, width=1.0, show=True):
    """Closed outlines ``(n, 2)`` as one trace (None between them)."""
    xs, ys = [], []
    for p in polys:
        p = np.asarray(p, dtype=float)
        xs += [*p[:, 0], p[0, 0], None]
        ys += [*p[:, 1], p[0, 1], None]
    fig.add_trace(go.Scatter(x=xs, y=ys, mode="lines", name=name, line=dict(color=color, width=width), showlegend=show))


def _equal(fig, title):
    fig.update_layout(title=title, height=640, template="plotly_white", legend=dict(orientation="h"))
    fig.update_yaxes(scaleanchor="x", scaleratio=1.0, title="y, mm")
    fig.update_xaxes(title="x, mm")


def _drive_figure(go, drive, w: dict, tightest):
    """The whole drive at the tightest spot's generator angle and section, the tightest teeth drawn over it."""
    name = drive.design.drive.name
    z = w.get("section_z_mm")
    st = deformed_state(drive, np.deg2rad(w["generator_angle_deg"]), drive.tol, z=z)
    fig = go.Figure()
    _lines(go, fig, [st.rigid_outline], "rigid gear", "#b00000")
    _lines(go, fig, [st.flex_outline], "flexspline (deformed)", "#0040c0")
    _lines(go, fig, [st.neutral], "neutral line", "#008000", width=0.8)
    teeth, labels, rig, overlaps, t_title, _ = tightest
    if overlaps:
        _lines(go, fig, overlaps, "overlap", "#ff8000", width=2.0)
    fig.add_trace(
        go.Scatter(
            x=[float(np.mean(teeth[3][:, 0]))],
            y=[float(np.mean(teeth[3][:, 1]))],
            mode="markers+text",
            marker=dict(size=10, color="#ff8000", symbol="x"),
            text=[f"tightest: {w['clearance_um']:.2f} um"],
            textposition="top center",
            name="tightest spot",
        )
    )
    _equal(
        fig,
        f"{name}: the drive at generator angle {w['generator_angle_deg']:g} deg"
        + ("" if z is None else f", section z = {z:g} mm")
        + " (zoom in on the cross to the tooth pair)",
    )
    return fig


def _tightest_figure(go, tightest):
    """The tightest spot, close up (the teeth around it in their own frame, as the PNG), the gap's two ends marked."""
    teeth, labels, rig, overlaps, t_title, spot = tightest
    fig = go.Figure()
    _lines(go, fig, list(rig), "rigid teeth", "#b00000")
    _lines(go, fig, list(teeth), "flexspline teeth", "#0040c0")
    if overlaps:
        _lines(go, fig, overlaps, "overlap", "#ff8000", width=2.0)
    if spot is not None:
        ends = np.stack([spot["flex"], spot["rigid"]])
        fig.add_trace(
            go.Scatter(
                x=ends[:, 0],
                y=ends[:, 1],
                mode="lines+markers",
                line=dict(color="#ff8000", width=2.0),
                marker=dict(size=7, color="#ff8000"),
                name=spot.get("label", f"tightest spot: {spot['um']:.2f} um") + " (zoom in)",
            )
        )
    _equal(fig, t_title)
    return fig


def _full_range_button(bottom: float, top: float, what: str) -> list:
    """A button pair beside a figure, under its legend: the band that matters (the first view) or the whole range
    (plotly's autorange, also a double-click on the plot)."""
    return [
        dict(
            type="buttons",
            direction="left",
            x=1.02,
            xanchor="left",
            y=0.0,
            yanchor="bottom",
            showactive=True,
            buttons=[
                dict(label=what, method="relayout", args=[{"yaxis.range": [bottom, top], "yaxis.autorange": False}]),
                dict(label="full range", method="relayout", args=[{"yaxis.autorange": True}]),
            ],
        )
    ]


def _profile_figure(go, profile):
    """Clearance along a tooth's passage, per section and flank, with the audit's figures marked; the first view on
    the PNG's band (the engagement, not the millimetres out of mesh), the full range one click away."""
    prof, p_title = profile
    fig = go.Figure()
    for sec in prof["sections"]:
        tag = "" if sec["z"] is None else f", z = {sec['z']:g} mm"
        fig.add_trace(go.Scatter(x=prof["phi_deg"], y=sec["working_um"], mode="lines", name=f"working flank{tag}"))
        fig.add_trace(
            go.Scatter(x=prof["phi_deg"], y=sec["nonworking_um"], mode="lines", name=f"non-working flank{tag}")
        )
    fig.add_trace(
        go.Scatter(
            x=[prof["worst_deg"], prof["entry_deg"]],
            y=[prof["worst_um"], prof["entry_um"]],
            mode="markers+text",
            text=[prof["worst_label"], prof["entry_label"]],
            textposition="top center",
            marker=dict(size=9, color="black"),
            name="the audit's figures",
        )
    )
    fig.add_hrect(y0=-prof["tol_um"], y1=prof["tol_um"], fillcolor="gray", opacity=0.2, line_width=0)
    bottom, top = profile_y_range(prof)
    fig.update_layout(
        title=p_title
        + f"<br><sub>shown up to {top:.0f} um (the engagement); full range: the button or a double-click</sub>",
        height=560,
        template="plotly_white",
        updatemenus=_full_range_button(bottom, top, f"up to {top:.0f} um"),
    )
    fig.update_xaxes(title="tooth angle from the major axis, deg")
    fig.update_yaxes(title="clearance, um (negative: overlap)", range=[bottom, top])
    return fig


def vs_angle_y_range(values, reported=None) -> tuple[float, float]:
    """The figure against generator angle's y range, um: the curves' own range (its ripple, the reason for the
    picture) and the audit's minimum, with a margin of 12 % of the ripple (at least 0.0025 um) either side."""
    v = np.concatenate([np.ravel(np.asarray(x, float)) for x in values])
    v = v[np.isfinite(v)]
    if reported is not None:
        v = np.append(v, reported)
    lo, hi = (float(v.min()), float(v.max())) if v.size else (0.0, 1.0)
    pad = max(0.12 * (hi - lo), VS_ANGLE_MIN_PAD_UM)
    return lo - pad, hi + pad


def _vs_angle_figure(go, vs_angle):
    """Clearance against generator angle (or every passage's entry gap of an imperfect drive), the first view on
    the data (the ripple), the full range one click away."""
    kind, args = vs_angle
    fig = go.Figure()
    if kind == "curve":
        ang, wv, nv, tol, v_title, reported = args
        fig.add_trace(go.Scatter(x=ang, y=wv, mode="lines", name="working flanks"))
        fig.add_trace(go.Scatter(x=ang, y=nv, mode="lines", name="non-working flanks"))
        if reported is not None:
            fig.add_trace(
                go.Scatter(
                    x=[ang[0], ang[-1]],
                    y=[reported, reported],
                    mode="lines",
                    line=dict(color="#c00000", dash="dot", width=1.2),
                    name=f"the audit's minimum {reported:.3f} um",
                )
            )
        bottom, top = vs_angle_y_range([wv, nv], reported)
        fig.update_xaxes(title="generator angle, deg")
    else:
        phi_h, gap, section, secs, perfect, tol, v_title = args
        fig.add_trace(go.Scatter(x=phi_h, y=gap, mode="markers", marker=dict(size=4), name="every passage's entry gap"))
        bottom, top = vs_angle_y_range([gap])
        fig.update_xaxes(title="generator angle of the passage, deg")
    fig.add_hrect(y0=-tol, y1=tol, fillcolor="gray", opacity=0.2, line_width=0)
    fig.update_layout(
        title=v_title,
        height=540,
        template="plotly_white",
        updatemenus=_full_range_button(bottom, top, "the data"),
    )
    fig.update_yaxes(title="clearance, um", range=[bottom, top])
    return fig


def audit_figures(drive, doc: dict, data: dict) -> dict:
    """The audit page's plotly figures, each a ``plotly.graph_objects.Figure`` to show or change (a notebook's):
    ``drive`` (the whole drive, the tightest spot marked), ``tightest``, ``profile`` (clearance along a tooth's
    passage), ``vs_angle`` (against generator angle). ``doc`` and ``data`` as for :func:`audit_html`."""
    require("html")
    import plotly.graph_objects as go

    return {
        "drive": _drive_figure(go, drive, doc["worst"], data["tightest"]),
        "tightest": _tightest_figure(go, data["tightest"]),
        "profile": _profile_figure(go, data["profile"]),
        "vs_angle": _vs_angle_figure(go, data["vs_angle"]),
    }


_NO_PINCH = "after the crossing the gaps never dip and rise again before the flanks engage"
_NO_CROSSING = "the tips never cross the rigid tip circle"


def _maybe_row(what: str, um, deg, why: str) -> tuple[str, str, str]:
    """A table row of a figure that may not exist: its value and tooth angle, or "none" and why."""
    if um is None:
        return (what, "none", why)
    return (what, f"{_fmt(um)} um", f"tooth angle {_fmt(deg)} deg")


def audit_html(drive, result, doc: dict, data: dict) -> str:
    """The page: verdict and figures of the audit (``doc``: :func:`wgcad.services.audit_report.audit_document`'s document;
    ``data``: :func:`wgcad.export.pictures.audit.audit_plot_data`)."""
    name = drive.design.drive.name
    w, e = doc["worst"], doc["entry"]
    ids = {"drive": "The whole drive", "tightest": "The tightest spot"}
    ids |= {"profile": "Clearance along a tooth's passage", "vs_angle": "Against generator angle"}
    figs = [(ids[k], _figure(fig, k)) for k, fig in audit_figures(drive, doc, data).items()]
    rows = [
        (
            "minimum clearance",
            f"{_fmt(w['clearance_um'])} um",
            f"{w['location']} at tooth angle {_fmt(w['tooth_angle_deg'])} deg",
        ),
        (
            "entry gap Delta [S1]",
            f"{_fmt(doc.get('entry_gap_um'))} um",
            f"{html.escape(str(e.get('kind') or '-'))}, {html.escape(str(e.get('edge') or '-'))} flank "
            f"at tooth angle {_fmt(e.get('tooth_angle_deg'))} deg",
        ),
        _maybe_row("tip crossing", e.get("crossing_um"), e.get("crossing_tooth_angle_deg"), _NO_CROSSING),
        _maybe_row("entry pinch", e.get("pinch_um"), e.get("pinch_tooth_angle_deg"), _NO_PINCH),
        (
            "backlash",
            f"{_fmt(doc.get('backlash_arcmin'), 4)} arcmin",
            f"{_fmt(doc.get('backlash_um_at_pitch'), 2)} um at the rigid pitch circle",
        ),
    ]
    verdict = (
        '<span class="bad">INTERFERENCE</span>' if doc["interference"] else '<span class="ok">no interference</span>'
    )
    table = "".join(f"<tr><th>{a}</th><td>{b}</td><td>{c}</td></tr>" for a, b, c in rows)
    st = doc["settings"]
    head = [
        f"<p>{verdict} (tolerance {_fmt(doc.get('interference_tol_um'), 3)} um); "
        f"{'figures on the exact tooth curves' if st.get('refined') else 'polygon figures'}; "
        f"{st.get('angles')} generator angles, sections {html.escape(str(st.get('sections_z_mm')))} mm.</p>",
        f"<table>{table}</table>",
        _notes(doc.get("not_checked", [])),
    ]
    return page(f"{name}: clearance audit", "audit", head, figs)
