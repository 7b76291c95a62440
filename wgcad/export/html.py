"""The audit as one self-contained, interactive page: zoomable figures (plotly, its script embedded) and the tables.

``wgcad audit --html PATH`` writes it. Nothing is fetched when the page is
viewed (plotly.js is inlined once, about 4.8 MB): it opens from a disk, a
mail or an archive. The figures are those of the PNGs
(:func:`wgcad.export.audit_figures.audit_plot_data`, computed once for
both) plus the whole drive at the tightest spot's generator angle, from
which a designer zooms down to the tooth pair and its microns.
"""

from __future__ import annotations

import html

import numpy as np

from .html_page import figure as _figure
from .html_page import fmt as _fmt
from .html_page import notes as _notes
from .html_page import page

__all__ = ["audit_html"]


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
    from ..placement.deformed import deformed_state

    name = drive.design.drive.name
    z = w.get("section_z_mm")
    st = deformed_state(drive, np.deg2rad(w["generator_angle_deg"]), drive.tol, z=z)
    fig = go.Figure()
    _lines(go, fig, [st.rigid_outline], "rigid gear", "#b00000")
    _lines(go, fig, [st.flex_outline], "flexspline (deformed)", "#0040c0")
    _lines(go, fig, [st.neutral], "neutral line", "#008000", width=0.8)
    teeth, labels, rig, overlaps, t_title = tightest
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
    """The tightest spot, close up (the teeth around it in their own frame, as the PNG)."""
    teeth, labels, rig, overlaps, t_title = tightest
    fig = go.Figure()
    _lines(go, fig, list(rig), "rigid teeth", "#b00000")
    _lines(go, fig, list(teeth), "flexspline teeth", "#0040c0")
    if overlaps:
        _lines(go, fig, overlaps, "overlap", "#ff8000", width=2.0)
    _equal(fig, t_title)
    return fig


def _profile_figure(go, profile):
    """Clearance along a tooth's passage, per section and edge, with the audit's figures marked."""
    prof, p_title = profile
    fig = go.Figure()
    for sec in prof["sections"]:
        tag = "" if sec["z"] is None else f", z = {sec['z']:g} mm"
        fig.add_trace(go.Scatter(x=prof["phi_deg"], y=sec["working_um"], mode="lines", name=f"working edge{tag}"))
        fig.add_trace(
            go.Scatter(x=prof["phi_deg"], y=sec["nonworking_um"], mode="lines", name=f"non-working edge{tag}")
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
    fig.update_layout(title=p_title, height=520, template="plotly_white")
    fig.update_xaxes(title="tooth angle from the major axis, deg")
    fig.update_yaxes(title="clearance, um (negative: overlap)")
    return fig


def _vs_angle_figure(go, vs_angle):
    """Clearance against generator angle (or every passage's entry gap of an imperfect drive)."""
    kind, args = vs_angle
    fig = go.Figure()
    if kind == "curve":
        ang, wv, nv, tol, v_title = args
        fig.add_trace(go.Scatter(x=ang, y=wv, mode="lines", name="working flanks"))
        fig.add_trace(go.Scatter(x=ang, y=nv, mode="lines", name="non-working flanks"))
        fig.update_xaxes(title="generator angle, deg")
    else:
        phi_h, gap, section, secs, perfect, tol, v_title = args
        fig.add_trace(go.Scatter(x=phi_h, y=gap, mode="markers", marker=dict(size=4), name="every passage's entry gap"))
        fig.update_xaxes(title="generator angle of the passage, deg")
    fig.add_hrect(y0=-tol, y1=tol, fillcolor="gray", opacity=0.2, line_width=0)
    fig.update_layout(title=v_title, height=520, template="plotly_white")
    fig.update_yaxes(title="clearance, um")
    return fig


def audit_html(drive, result, doc: dict, data: dict) -> str:
    """The page: verdict and figures of the audit (``doc``: :func:`wgcad.report.audit_run.audit_document`'s document;
    ``data``: :func:`wgcad.export.audit_figures.audit_plot_data`)."""
    import plotly.graph_objects as go

    name = drive.design.drive.name
    w, e = doc["worst"], doc["entry"]
    figs = [
        ("The whole drive", _figure(_drive_figure(go, drive, w, data["tightest"]), "drive")),
        ("The tightest spot", _figure(_tightest_figure(go, data["tightest"]), "tightest")),
        ("Clearance along a tooth's passage", _figure(_profile_figure(go, data["profile"]), "profile")),
        ("Against generator angle", _figure(_vs_angle_figure(go, data["vs_angle"]), "vs_angle")),
    ]
    rows = [
        (
            "minimum clearance",
            f"{_fmt(w['clearance_um'])} um",
            f"{w['location']} at tooth angle {_fmt(w['tooth_angle_deg'])} deg",
        ),
        (
            "entry gap Delta [S1]",
            f"{_fmt(doc.get('entry_gap_um'))} um",
            f"{html.escape(str(e.get('kind') or '-'))}, {html.escape(str(e.get('edge') or '-'))} edge "
            f"at tooth angle {_fmt(e.get('tooth_angle_deg'))} deg",
        ),
        (
            "tip crossing",
            f"{_fmt(e.get('crossing_um'))} um",
            f"tooth angle {_fmt(e.get('crossing_tooth_angle_deg'))} deg",
        ),
        ("entry pinch", f"{_fmt(e.get('pinch_um'))} um", f"tooth angle {_fmt(e.get('pinch_tooth_angle_deg'))} deg"),
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
