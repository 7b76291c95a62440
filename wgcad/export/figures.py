"""PNG pictures of a drive in a deformed state: the whole drive and an unrolled close-up of the mesh."""

from __future__ import annotations

import io
from math import pi

import numpy as np

__all__ = ["assembly_png"]


def _unroll(pts: np.ndarray, r_ref: float, a_ref: float) -> np.ndarray:
    """Polar -> (arc length at r_ref from angle a_ref, radius - r_ref), mm: radial gaps stay true."""
    ang = np.arctan2(pts[..., 1], pts[..., 0]) - a_ref
    ang = (ang + pi) % (2 * pi) - pi
    return np.stack([r_ref * ang, np.hypot(pts[..., 0], pts[..., 1]) - r_ref], axis=-1)


def assembly_png(scene: dict, title: str, entry_deg: float = 50.0, rows: int = 3) -> bytes:
    """Render a deformed state to PNG bytes.

    Parameters
    ----------
    scene : dict
        ``flex_teeth`` (K, N, 2) placed flexspline teeth (rigid frame drawn),
        ``flex_phi`` (K,) their angles from the major axis (rad),
        ``rigid_outline`` (M, 2), ``flex_outline`` (P, 2), ``flex_rim`` (Q, 2),
        ``rigid_rim_radius``, ``major_axis`` (rad, drawing frame),
        ``entry_sign`` (+1: teeth enter at positive phi, i.e. ccw rotation),
        ``r_ref`` radius for the unrolled view.
    title : str
    entry_deg : float
        Close-up span from the major axis toward the entry side, degrees.
    rows : int
        The close-up is split into this many strips.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    fig = plt.figure(figsize=(16, 4.2 + 2.4 * rows), dpi=90)
    gs = fig.add_gridspec(rows, 2, width_ratios=[1, 2.6])
    ax0 = fig.add_subplot(gs[:, 0])
    ro, fo, fr = scene["rigid_outline"], scene["flex_outline"], scene["flex_rim"]
    ax0.fill(*ro.T, color="0.80", lw=0)
    ax0.plot(*np.vstack([ro, ro[:1]]).T, color="0.3", lw=0.4)
    t = np.linspace(0, 2 * pi, 721)
    ax0.plot(scene["rigid_rim_radius"] * np.cos(t), scene["rigid_rim_radius"] * np.sin(t), color="0.3", lw=0.6)
    ax0.fill(*fo.T, color="tab:blue", alpha=0.35, lw=0)
    ax0.plot(*np.vstack([fo, fo[:1]]).T, color="tab:blue", lw=0.4)
    ax0.fill(*fr.T, color="white", lw=0)
    ax0.plot(*np.vstack([fr, fr[:1]]).T, color="tab:blue", lw=0.6)
    a = scene["major_axis"]
    R = scene["rigid_rim_radius"]
    for s in (1, -1):
        ax0.annotate("", xy=(s * R * np.cos(a), s * R * np.sin(a)), xytext=(0, 0), arrowprops=dict(arrowstyle="->", color="tab:red", lw=1.2))
    ax0.text(1.02 * R * np.cos(a), 1.02 * R * np.sin(a), "major axis", color="tab:red", fontsize=8)
    ax0.set_aspect("equal")
    ax0.set_title("whole drive (deformation to scale)", fontsize=9)
    ax0.axis("off")

    # close-up: unrolled strips from just behind the major axis to the entry side
    r_ref, sgn = scene["r_ref"], scene["entry_sign"]
    span = np.deg2rad(entry_deg)
    edges = np.linspace(-np.deg2rad(4.0), span, rows + 1)
    teeth, phi = scene["flex_teeth"], scene["flex_phi"]
    phi_w = (phi + pi) % (2 * pi) - pi
    rig_u = _unroll(ro, r_ref, a)
    rig_u = np.roll(rig_u, -int(np.argmin(rig_u[:, 0])), axis=0)  # start at the wrap (opposite the window)
    for i in range(rows):
        ax = fig.add_subplot(gs[i, 1])
        lo, hi = edges[i], edges[i + 1]
        x_lo, x_hi = sorted((sgn * r_ref * lo, sgn * r_ref * hi))
        pad = 0.6 * scene["module"]
        sel = (rig_u[:, 0] > x_lo - 3 * pad) & (rig_u[:, 0] < x_hi + 3 * pad)
        if sel.any():
            # polygon of the rigid teeth in this strip, closed through the rim side
            seg = rig_u[sel]
            yb = seg[:, 1].max() + 0.5 * scene["module"] if scene["rigid_outward"] else seg[:, 1].min() - 0.5 * scene["module"]
            poly = np.vstack([seg, [[seg[-1, 0], yb], [seg[0, 0], yb]]])
            ax.add_patch(Polygon(poly, closed=True, fc="0.80", ec="0.3", lw=0.6))
        for k in np.nonzero((sgn * phi_w >= lo - 0.02) & (sgn * phi_w <= hi + 0.02))[0]:
            tu = _unroll(teeth[k], r_ref, a)
            ax.add_patch(Polygon(tu, closed=True, fc="tab:blue", alpha=0.45, ec="tab:blue", lw=0.6))
            top = tu[:, 1].max() if scene["rigid_outward"] else tu[:, 1].min()
            cx = tu[np.argmax(tu[:, 1]) if scene["rigid_outward"] else np.argmin(tu[:, 1]), 0]
            if x_lo - pad <= cx <= x_hi + pad:
                ax.text(cx, top + (0.15 if scene["rigid_outward"] else -0.25) * scene["module"], f"{np.rad2deg(phi_w[k]):.1f}°",
                        ha="center", fontsize=6.5, color="tab:blue")
        ax.set_xlim(x_lo - pad, x_hi + pad)
        ys = scene["y_range"]
        ax.set_ylim(*ys)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
        ax.set_ylabel("R - r_ref, mm", fontsize=7)
        if i == rows - 1:
            ax.set_xlabel(f"arc length at r_ref = {r_ref:.2f} mm from the major axis, mm (entry side {'+' if sgn > 0 else '-'})", fontsize=8)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
