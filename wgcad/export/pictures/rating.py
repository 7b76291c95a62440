"""The pictures of ``wgcad rating``: wind-up with its three-segment fit, the flexspline's stress around the rim, the criteria against torque, and the friction panels (docs/models.md 10)."""

from __future__ import annotations

import numpy as np

from wgcad.units import ARCMIN_PER_RAD, UM_PER_MM

from .friction import efficiency_panel, input_panel, loop_panel
from .mpl import png_bytes, pyplot

#: the legends' font, points (the pictures' smallest font is 8 pt, :data:`wgcad.export.pictures.drive.MIN_FONT_PT`)
LEGEND_PT = 8.5

__all__ = ["LEGEND_PT", "rating_figure", "rating_png"]


def _wind_up(ax, ds):
    if ds.fit is None:
        ax.text(0.5, 0.5, "no rated torque:\nno wind-up curve", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    T = np.array([c[0] for c in ds.curve])
    th = ARCMIN_PER_RAD * np.array([c[1] for c in ds.curve])
    ax.plot(T, th, "o", ms=4, label="elastic model")
    Tf = np.linspace(0.0, T.max(), 200)
    f = ds.fit
    ax.plot(
        Tf,
        ARCMIN_PER_RAD * f.wind_up(Tf),
        "-",
        lw=1.2,
        label=(f"fit: K1 {f.k1:.3g}, K2 {f.k2:.3g}, K3 {f.k3:.3g} N m/rad"),
    )
    for t, name in ((f.t1, "T1"), (f.t2, "T2")):
        ax.axvline(t, color="0.6", lw=0.8, ls=":")
        ax.text(t, ax.get_ylim()[1], f" {name}", fontsize=8, va="top")
    ax.set_xlabel("output torque, N m")
    ax.set_ylabel("wind-up, arcmin")
    ax.set_title("torsional wind-up (free play included)", fontsize=9)
    ax.legend(fontsize=LEGEND_PT, loc="lower right")


def _stress(ax, ds):
    pairs = [(ds.levels[0], ":", "no load")] + ([(ds.rated, "-", f"{ds.rated_torque_nm:.0f} N m")] if ds.fit else [])
    for lv, ls, label in pairs:
        for s in lv.stresses:
            if s.where != "root" and lv is ds.levels[0] and ds.fit:
                continue
            name = {
                "root": "roots",
                "cup": "cup wall",
                "diaphragm_hub": "diaphragm hub",
                "diaphragm_wall": "diaphragm edge",
            }[s.where]
            name = f"{name} z {s.z:g}"
            note = "" if s.rated else ", not rated: derived sizes"
            style = ls if s.rated else "--"
            ax.plot(
                np.rad2deg(s.psi),
                s.sigma,
                style,
                lw=1.0 if s.rated else 0.8,
                label=f"{name} mm, {label} (n {s.safety:.2f}{note})",
            )
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_xlabel("angle from the generator's major axis, deg")
    ax.set_ylabel("surface stress, MPa (tension +)")
    ax.set_title("flexspline stress around the rim (n: Goodman safety)", fontsize=9)
    ax.legend(fontsize=LEGEND_PT, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.14))


def _criteria(ax, ds):
    ld = ds.design.load
    T = np.array([lv.torque_nm for lv in ds.levels])
    sf = np.array([lv.safety for lv in ds.levels])
    life = np.array([lv.life_h for lv in ds.levels])
    ax.plot(T, sf / ld.fatigue_safety_min, "-o", ms=3, label="Goodman safety / required")
    ax.plot(T, life / ld.required_life_h, "-s", ms=3, label="bearing L10 / required")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_yscale("log")
    ax.axvline(
        ds.rated_torque_nm,
        color="r",
        lw=1.0,
        ls="--",
        label=f"rated {ds.rated_torque_nm:.0f} N m ({ds.binding})" if ds.fit else f"no rated torque ({ds.binding})",
    )
    ax.set_xlabel("output torque, N m")
    ax.set_ylabel("ratio to the required value (above 1: met)")
    ax.set_title("criteria against torque", fontsize=9)
    ax.grid(True, alpha=0.3)
    um = ax.twinx()
    um.plot(T, [UM_PER_MM * lv.entry_gap for lv in ds.levels], "-^", color="tab:green", ms=3, label="entry gap, um")
    um.plot(
        T, [UM_PER_MM * lv.depth.min() for lv in ds.levels], "-d", color="tab:red", ms=3, label="engagement depth, um"
    )
    um.axhline(0.0, color="tab:green", lw=0.8, ls=":")
    um.set_ylabel("um (below 0: tips interfere / teeth skip)")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = um.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=LEGEND_PT, loc="center right")


def rating_png(ds) -> bytes:
    """One PNG with the six panels of the datasheet: wind-up, stress, criteria; efficiency, hysteresis, input torque."""
    return png_bytes(rating_figure(ds), bbox_inches="tight", metadata={"Software": None})


def rating_figure(ds):
    """The datasheet's figure (:func:`rating_png`); its legends at :data:`LEGEND_PT` (they were 6 and 7 pt, unreadable
    at the picture's width), laid out with them (constrained layout)."""
    plt = pyplot()
    fig = plt.figure(figsize=(18.0, 13.0), dpi=110, layout="constrained")
    axs = fig.subplots(2, 3, height_ratios=[1.25, 1.0])
    _wind_up(axs[0, 0], ds)
    _stress(axs[0, 1], ds)
    _criteria(axs[0, 2], ds)
    efficiency_panel(axs[1, 0], ds)
    loop_panel(axs[1, 1], ds)
    input_panel(axs[1, 2], ds)
    head = f"rated {ds.rated_torque_nm:.0f} N m, bound by" if ds.fit else "NO RATED TORQUE: fails at no load:"
    fig.suptitle(f"{ds.design.drive.name}: datasheet ({head} {ds.binding})", fontsize=12)
    return fig
