"""``wgcad audit --torque-nm ... --html``: the load audit as one interactive page: entry gap, tooth forces and ball loads, wind-up against torque, and the table of levels (docs/models.md 4.1, 5)."""

from __future__ import annotations

import html

from ...extras import require
from .frame import figure, fmt, page, table

__all__ = ["load_html", "load_figures"]


def _entry(go, res):
    fig = go.Figure()
    T = [lv["torque_nm"] for lv in res["levels"]]
    fig.add_trace(
        go.Scatter(x=T, y=[lv["entry_gap_um"] for lv in res["levels"]], name="entry gap (smallest)", line=dict(width=3))
    )
    # each section and wave: where the smallest lies
    n = len(res["levels"][0]["entry"])
    for j in range(n):
        e0 = res["levels"][0]["entry"][j]
        fig.add_trace(
            go.Scatter(
                x=T,
                y=[lv["entry"][j]["entry_gap_um"] for lv in res["levels"]],
                name=f"wave {e0['wave']}, z {e0['section_z_mm']:g} mm",
                line=dict(width=1, dash="dot"),
            )
        )
    fig.add_trace(
        go.Scatter(x=T, y=[lv["crossing_gap_um"] for lv in res["levels"]], name="tip crossing", line=dict(dash="dash"))
    )
    tol = res["interference_tol_um"]
    fig.add_hrect(y0=-tol, y1=tol, fillcolor="gray", opacity=0.2, line_width=0)
    fig.update_layout(
        title="entry gap Delta [S1] against output torque (below 0: the tips interfere)",
        height=520,
        template="plotly_white",
    )
    fig.update_xaxes(title="output torque, N m")
    fig.update_yaxes(title="um")
    return fig


def _forces(go, res):
    from plotly.subplots import make_subplots

    fig = make_subplots(
        rows=2, cols=1, shared_xaxes=True, subplot_titles=("tooth forces (all sections and flanks)", "ball loads")
    )
    for lv in res["levels"]:
        name = f"{lv['torque_nm']:g} N m"
        fig.add_trace(
            go.Scatter(x=lv["tooth_angle_deg"], y=lv["tooth_force_n"], name=name, legendgroup=name), row=1, col=1
        )
        fig.add_trace(
            go.Scatter(
                x=lv["ball_angle_deg"],
                y=lv["ball_load_n"],
                mode="lines+markers",
                name=name,
                legendgroup=name,
                showlegend=False,
            ),
            row=2,
            col=1,
        )
    fig.update_xaxes(title="angle from the generator's major axis, deg", row=2, col=1)
    fig.update_yaxes(title="N", row=1, col=1)
    fig.update_yaxes(title="N", row=2, col=1)
    fig.update_layout(height=720, template="plotly_white", title="forces around the rim, one curve per torque")
    return fig


def _wind_up(go, res):
    fig = go.Figure()
    T = [lv["torque_nm"] for lv in res["levels"]]
    fig.add_trace(
        go.Scatter(x=T, y=[lv["wind_up_arcmin"] for lv in res["levels"]], mode="lines+markers", name="output wind-up")
    )
    fig.add_trace(
        go.Scatter(x=T, y=[lv["mesh_wind_up_arcmin"] for lv in res["levels"]], mode="lines+markers", name="mesh only")
    )
    fig.update_layout(title="wind-up against torque (the free play included)", height=460, template="plotly_white")
    fig.update_xaxes(title="output torque, N m")
    fig.update_yaxes(title="arcmin")
    return fig


def load_figures(res: dict) -> dict:
    """The load page's plotly figures (``plotly.graph_objects.Figure``): ``entry_gap`` (the load curve: entry gap
    against torque), ``forces`` (around the rim), ``wind_up``; ``res`` the load audit's document."""
    require("html")
    import plotly.graph_objects as go

    return {"entry_gap": _entry(go, res), "forces": _forces(go, res), "wind_up": _wind_up(go, res)}


def load_html(res: dict) -> str:
    """The page of a load audit's document (:func:`wgcad.elastic.sweep.torque_sweep` without its states)."""
    name = res["design"]
    closes = res["entry_gap_closes"]
    verdict = (
        "<p><span class='bad'>ENTRY GAP CLOSES under load</span>: tip interference</p>"
        if closes
        else "<p><span class='ok'>the entry gap stays open</span> at every torque asked</p>"
    )
    rows = []
    for k, lv in enumerate(res["levels"]):
        at = lv.get("entry_gap_at") or {}
        rows.append(
            (
                f"{lv['torque_nm']:g}",
                fmt(lv["entry_gap_um"], 3),
                html.escape(
                    f"{at.get('tooth_angle_deg', '-')} deg, z {at.get('section_z_mm', '-')} mm, {at.get('edge', '-')}"
                ),
                fmt(lv["crossing_gap_um"], 3),
                str(lv["teeth_in_contact"]),
                fmt(lv["largest_tooth_force_n"], 1),
                fmt(lv["max_ball_load_n"], 1),
                fmt(lv["max_ball_pressure_mpa"], 0),
                fmt(lv["wind_up_arcmin"], 4),
                fmt(res["secant_stiffness_nm_per_rad"][k], 0),
            )
        )
    levels = table(
        rows,
        head=[
            "torque, N m",
            "entry gap, um",
            "where",
            "tip crossing, um",
            "teeth in contact",
            "max tooth force, N",
            "max ball load, N",
            "ball pressure, MPa",
            "wind-up, arcmin",
            "secant stiffness, N m/rad",
        ],
    )
    head = [
        verdict,
        f"<p>elastic contact model, {len(res['model']['sections_z_mm'])} sections; cam offset "
        f"{res['cam_offset_um']:g} um at {res['cam_offset_deg']:g} deg.</p>",
        levels,
    ]
    titles = {"entry_gap": "Entry gap against torque", "forces": "Forces around the rim", "wind_up": "Wind-up"}
    figs = [(titles[k], figure(fig, k)) for k, fig in load_figures(res).items()]
    return page(f"{name}: under load", "audit --torque-nm", head, figs)
