"""The datasheet's friction panels (matplotlib): efficiency against torque at each speed, the hysteresis loop, the
input torque's parts (docs/models.md 10.8)."""

from __future__ import annotations

import numpy as np

from wgcad.units import ARCMIN_PER_RAD

__all__ = ["efficiency_panel", "loop_panel", "input_panel"]


def _none(ax, what: str) -> None:
    ax.text(0.5, 0.5, f"no rated torque:\nno {what}", ha="center", va="center", transform=ax.transAxes)
    ax.set_axis_off()


def efficiency_panel(ax, ds) -> None:
    fr = ds.friction
    if fr is None:
        return _none(ax, "efficiency")
    eff = fr.efficiency
    T = np.array([p.torque_nm for p in eff.points])
    for j, n in enumerate(eff.speeds_rpm):
        ax.plot(T[1:], 100.0 * eff.table[1:, j], "-o", ms=3, label=f"{n:g} rpm")
    ax.set_xlabel("output torque, N m")
    ax.set_ylabel("efficiency, %")
    ax.set_ylim(0, 100)
    ax.set_title(f"efficiency (teeth mu {fr.setup.mu:g}, bearing viscosity {fr.setup.nu_cst:g} mm^2/s)", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8.5, loc="lower right", title="input speed", title_fontsize=8.5)


def loop_panel(ax, ds) -> None:
    fr = ds.friction
    if fr is None:
        return _none(ax, "hysteresis loop")
    loop = fr.loop
    up_T, up_th, dn_T, dn_th = loop.branches()
    ax.plot(up_T, ARCMIN_PER_RAD * up_th, "-", lw=1.2, label="loading (rising torque)")
    ax.plot(dn_T, ARCMIN_PER_RAD * dn_th, "-", lw=1.2, label="unloading (falling torque)")
    h = ARCMIN_PER_RAD * loop.hysteresis_loss
    ax.plot([0, 0], [-h / 2, h / 2], "k-", lw=2.0, label=f"hysteresis loss {h:.2f} arcmin")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.axvline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("output torque, N m")
    ax.set_ylabel("wind-up, arcmin")
    ax.set_title(
        f"hysteresis loop, generator held (width {loop.width_nm:.1f} N m, {1e3 * loop.loss_j:.1f} mJ per cycle)",
        fontsize=9,
    )
    ax.legend(fontsize=8.5, loc="upper left")


def input_panel(ax, ds) -> None:
    fr = ds.friction
    if fr is None:
        return _none(ax, "input torque")
    pts = fr.efficiency.points
    su = fr.setup
    T = np.array([p.torque_nm for p in pts])
    ideal = 1e-3 * 1e3 * T / su.ratio
    teeth = 1e-3 * np.array([p.teeth.loss for p in pts])
    load = 1e-3 * su.ring_rate * np.array([p.bearing().load for p in pts])
    visc = 1e-3 * su.ring_rate * np.array([p.bearing().viscous for p in pts])
    bands = [ideal, visc, load, teeth]
    labels = ["output torque / ratio", "bearing, viscous term", "bearing, load term", "tooth friction"]
    if su.seal_nmm:
        bands.append(np.full(len(T), 1e-3 * su.ring_rate * su.seal_nmm))
        labels.append("bearing seals")
    ax.stackplot(T, *bands, labels=labels, alpha=0.8)
    ax.set_xlabel("output torque, N m")
    ax.set_ylabel(f"input torque at {ds.speed_rpm:g} rpm, N m")
    ax.set_title(
        f"input torque: no-load running {fr.efficiency.no_load_nm:.2f} N m, starting {fr.efficiency.starting_nm:.3f} N m",
        fontsize=9,
    )
    ax.legend(fontsize=8.5, loc="upper left")
