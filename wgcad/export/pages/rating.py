"""``wgcad rating --html``: the datasheet as one interactive page: the limits, the wind-up with its fit, the stress around the rim, the criteria against torque (docs/models.md 10)."""

from __future__ import annotations

import html

import numpy as np

from wgcad.units import ARCMIN_PER_RAD, UM_PER_MM

from ...extras import require
from .frame import figure, fmt, notes, page, table

__all__ = ["rating_html"]

_NAMES = {
    "root": "tooth roots",
    "cup": "cup wall",
    "diaphragm_hub": "diaphragm at hub",
    "diaphragm_wall": "diaphragm at wall",
}


def _wind_up(go, ds):
    fig = go.Figure()
    T = np.array([c[0] for c in ds.curve])
    th = ARCMIN_PER_RAD * np.array([c[1] for c in ds.curve])
    fig.add_trace(go.Scatter(x=T, y=th, mode="markers", name="elastic model"))
    f = ds.fit
    Tf = np.linspace(0.0, T.max(), 300)
    fig.add_trace(
        go.Scatter(
            x=Tf,
            y=ARCMIN_PER_RAD * f.wind_up(Tf),
            mode="lines",
            name=f"fit: K1 {f.k1:.3g}, K2 {f.k2:.3g}, K3 {f.k3:.3g} N m/rad",
        )
    )
    for t, name in ((f.t1, "T1"), (f.t2, "T2")):
        fig.add_vline(x=t, line_dash="dot", line_color="gray", annotation_text=name)
    fig.update_layout(title="torsional wind-up (free play included)", height=480, template="plotly_white")
    fig.update_xaxes(title="output torque, N m")
    fig.update_yaxes(title="wind-up, arcmin")
    return fig


def _stress(go, ds):
    fig = go.Figure()
    levels = [(ds.levels[0], "no load", "dot")]
    if ds.fit is not None:
        levels.append((ds.rated, f"{ds.rated_torque_nm:.0f} N m", "solid"))
    for lv, label, dash in levels:
        for s in lv.stresses:
            note = "" if s.rated else ", not rated: derived sizes"
            fig.add_trace(
                go.Scatter(
                    x=np.rad2deg(s.psi),
                    y=s.sigma,
                    mode="lines",
                    line=dict(dash=dash if s.rated else "dash", width=1.2 if s.rated else 0.8),
                    name=f"{_NAMES[s.where]} z {s.z:g} mm, {label} (Goodman {s.safety:.2f}{note})",
                )
            )
    fig.update_layout(
        title="flexspline stress around the rim (a fibre's cycle over a turn)", height=560, template="plotly_white"
    )
    fig.update_xaxes(title="angle from the generator's major axis, deg", range=[0, 360], dtick=45)
    fig.update_yaxes(title="surface stress, MPa (tension +)")
    return fig


def _criteria(go, ds):
    from plotly.subplots import make_subplots

    ld = ds.design.load
    T = [lv.torque_nm for lv in ds.levels]
    fig = make_subplots(specs=[[{"secondary_y": True}]])
    fig.add_trace(
        go.Scatter(x=T, y=[lv.safety / ld.fatigue_safety_min for lv in ds.levels], name="Goodman safety / required")
    )
    fig.add_trace(
        go.Scatter(x=T, y=[lv.life_h / ld.required_life_h for lv in ds.levels], name="bearing L10 / required")
    )
    fig.add_trace(
        go.Scatter(x=T, y=[UM_PER_MM * lv.entry_gap for lv in ds.levels], name="entry gap, um"), secondary_y=True
    )
    fig.add_trace(
        go.Scatter(x=T, y=[UM_PER_MM * lv.depth.min() for lv in ds.levels], name="engagement depth, um"),
        secondary_y=True,
    )
    fig.add_hline(y=1.0, line_color="black", line_width=1)
    fig.add_vline(x=ds.rated_torque_nm, line_color="red", line_dash="dash", annotation_text=f"rated ({ds.binding})")
    fig.update_yaxes(type="log", title="ratio to the required value (above 1: met)", secondary_y=False)
    fig.update_yaxes(title="um (below 0: tips interfere / teeth skip)", secondary_y=True)
    fig.update_xaxes(title="output torque, N m")
    fig.update_layout(title="criteria against torque", height=520, template="plotly_white")
    return fig


def _efficiency(go, ds):
    fig = go.Figure()
    eff = ds.friction.efficiency
    T = [p.torque_nm for p in eff.points[1:]]
    for j, n in enumerate(eff.speeds_rpm):
        fig.add_trace(go.Scatter(x=T, y=100.0 * eff.table[1:, j], mode="lines+markers", name=f"{n:g} rpm"))
    su = ds.friction.setup
    fig.update_layout(
        title=f"efficiency against output torque (teeth mu {su.mu:g}, bearing viscosity {su.nu_cst:g} mm^2/s)",
        height=480,
        template="plotly_white",
    )
    fig.update_xaxes(title="output torque, N m")
    fig.update_yaxes(title="efficiency, %", range=[0, 100])
    return fig


def _loop(go, ds):
    fig = go.Figure()
    loop = ds.friction.loop
    up_T, up_th, dn_T, dn_th = loop.branches()
    fig.add_trace(go.Scatter(x=up_T, y=ARCMIN_PER_RAD * up_th, mode="lines", name="loading (rising torque)"))
    fig.add_trace(go.Scatter(x=dn_T, y=ARCMIN_PER_RAD * dn_th, mode="lines", name="unloading (falling torque)"))
    fig.update_layout(
        title=f"hysteresis loop, generator held (width {loop.width_nm:.1f} N m, {1e3 * loop.loss_j:.1f} mJ per cycle)",
        height=480,
        template="plotly_white",
    )
    fig.update_xaxes(title="output torque, N m")
    fig.update_yaxes(title="wind-up, arcmin")
    return fig


def _friction_rows(ds) -> list:
    fr = ds.friction
    eff, loop, rated = fr.efficiency, fr.loop, fr.rated
    lm_T = 0.04 * ds.rated_torque_nm
    back = "self-locking" if eff.self_locking else f"{eff.backdriving_nm:.1f} N m at the output"
    return [
        (
            "efficiency at rated",
            f"{100 * rated.efficiency():.1f} %",
            f"output / input power over a generator turn at {ds.speed_rpm:g} rpm (teeth mu {fr.setup.mu:g})",
        ),
        (
            "no-load running torque",
            f"{eff.no_load_nm:.3f} N m",
            f"input torque at zero output torque, {ds.speed_rpm:g} rpm",
        ),
        ("starting torque", f"{eff.starting_nm:.3f} N m", "input torque at zero output torque, creep speed"),
        ("backdriving torque", back, "output torque that turns the free input"),
        (
            "hysteresis loss",
            f"{ARCMIN_PER_RAD * loop.hysteresis_loss:.2f} arcmin",
            f"at zero torque after +-{ds.rated_torque_nm:.0f} N m (free play included); lost motion at "
            f"+-{lm_T:.0f} N m {ARCMIN_PER_RAD * loop.lost_motion(lm_T):.2f} arcmin",
        ),
    ]


def _how(lim) -> str:
    """How a limit was found, with the bisection's bracket where there is one."""
    if lim.bracket is None:
        return lim.note
    return f"{lim.note}; between {lim.bracket[0]:.0f} (met) and {lim.bracket[1]:.0f} N m (failed)"


def rating_html(ds) -> str:
    """The page of a :class:`~wgcad.rating.datasheet.Datasheet`."""
    require("html")  # plotly draws the page
    import plotly.graph_objects as go

    from wgcad.rating.datasheet import CRITERIA

    name = ds.design.drive.name
    verdict = (
        f"<p><span class='ok'>rated torque {ds.rated_torque_nm:.0f} N m</span>, bound by <b>{ds.binding}</b>: "
        f"{html.escape(CRITERIA[ds.binding])}</p>"
        if ds.rated_torque_nm > 0
        else f"<p><span class='bad'>NO RATED TORQUE</span>: {ds.binding} fails at no load</p>"
    )
    limits = table(
        [
            (k, ("&gt; " if v.above else "") + f"{v.torque_nm:.0f}", html.escape(CRITERIA[k]), html.escape(_how(v)))
            for k, v in ds.limits.items()
        ],
        head=["criterion", "limit, N m", "asks", "how found"],
    )
    rows = [
        ("tooth-root K_t (FE)", fmt(ds.kt.kt, 3), f"K_f {ds.setup.kf:.3f} with notch sensitivity {ds.setup.q:.3f}"),
        (
            "endurance limit S_e",
            f"{ds.setup.strength.endurance:.0f} MPa",
            html.escape("; ".join(ds.setup.strength.assumed) or "-"),
        ),
        ("bearing L10 at rated", f"{ds.rated.life.l10_h:.0f} h", f"{ds.speed_rpm:g} rpm input"),
    ]
    if ds.fit is not None:
        f = ds.fit
        rows += [
            ("stiffness", f"K1 {f.k1:.3g}, K2 {f.k2:.3g}, K3 {f.k3:.3g} N m/rad", f"T1 {f.t1:.0f}, T2 {f.t2:.0f} N m"),
            (
                "wind-up offset, lost motion",
                f"{ARCMIN_PER_RAD * ds.windup_offset:.2f}, {ARCMIN_PER_RAD * ds.lost_motion:.2f} arcmin",
                "wind-up offset: the stiffness fit's intercept (not the audit's backlash); "
                f"lost motion at +-4 % of the rated torque ({0.04 * ds.rated_torque_nm:.0f} N m)",
            ),
        ]
    if ds.friction is not None:
        rows += _friction_rows(ds)
    r = ds.ratcheting
    rows.append(("ratcheting", ("above " if r["above"] else "") + f"{r['torque_nm']:.0f} N m", html.escape(r["note"])))
    stress = table(
        [
            (
                f"{_NAMES[s.where]} z {s.z:g} mm",
                f"{s.nominal:.0f}",
                f"{s.sigma.min():.0f} .. {s.sigma.max():.0f}",
                f"{s.shear:.1f}",
                fmt(s.safety, 2) + ("" if s.rated else " (not rated)"),
                fmt(s.yield_safety, 2),
            )
            for s in ds.rated.stresses
        ],
        head=[
            "at the rated torque",
            "nominal bending, MPa",
            "stress, MPa",
            "shear, MPa",
            "Goodman safety",
            "yield safety",
        ],
    )
    head = [verdict, limits, table(rows), stress, notes(ds.notes)]
    figs = []
    if ds.fit is not None:
        figs.append(("Wind-up and the catalogue's three segments", figure(_wind_up(go, ds), "wind_up")))
    figs.append(("Stress around the rim", figure(_stress(go, ds), "stress")))
    figs.append(("Criteria against torque", figure(_criteria(go, ds), "criteria")))
    if ds.friction is not None:
        figs.append(("Efficiency against torque and speed", figure(_efficiency(go, ds), "efficiency")))
        figs.append(("Hysteresis loop", figure(_loop(go, ds), "hysteresis")))
    return page(f"{name}: datasheet", "rating", head, figs)
