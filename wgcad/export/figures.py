"""PNG pictures of a drive in a deformed state: the whole drive and an unrolled close-up of the mesh."""

from __future__ import annotations

import io
from math import pi

import numpy as np

__all__ = ["assembly_png", "clearance_profile_png", "clearance_vs_angle_png", "tightest_spot_png"]


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
    # schematic of the whole drive: the neutral line with its deformation exaggerated
    # (at true scale W0 is ~1 % of the radius and the oval cannot be seen)
    r_m, w0 = scene["r_m"], abs(scene["w0"])
    k = max(1.0, round(0.12 * r_m / w0))
    t = np.linspace(0, 2 * pi, 721)
    ro_r = scene["rigid_rim_radius"]
    ax0.plot(ro_r * np.cos(t), ro_r * np.sin(t), color="0.3", lw=0.8)
    ax0.plot(r_m * np.cos(t), r_m * np.sin(t), color="0.6", lw=0.8, ls=":", label="undeformed neutral line")
    pn = scene["neutral_phi"]
    rr = r_m + k * scene["neutral_w"]
    ax0.plot(rr * np.cos(pn), rr * np.sin(pn), color="tab:blue", lw=1.6, label=f"deformed neutral line (w x {k:g})")
    a = scene["major_axis"]
    for s_, col, name in ((0.0, "tab:red", "major axis"), (pi / scene["waves"], "tab:green", "minor axis")):
        aa = a + s_
        ax0.plot([-ro_r * np.cos(aa), ro_r * np.cos(aa)], [-ro_r * np.sin(aa), ro_r * np.sin(aa)], color=col, lw=1.0, ls="--")
        ax0.text(1.03 * ro_r * np.cos(aa), 1.03 * ro_r * np.sin(aa), name, color=col, fontsize=8, ha="center")
    ax0.set_aspect("equal")
    ax0.set_title(f"whole drive, schematic: deformation exaggerated x{k:g}", fontsize=9)
    ax0.legend(fontsize=7, loc="lower center", bbox_to_anchor=(0.5, -0.12))
    ax0.axis("off")
    ro = scene["rigid_outline"]

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


def clearance_profile_png(profile: dict, title: str) -> bytes:
    """Per-tooth clearance against the tooth's angle from the major axis, per flank and section.

    ``profile``: ``phi_deg`` (P,), ``sections`` list of dicts with ``z``,
    ``working_um``, ``nonworking_um`` (P,) arrays; ``entry_deg``,
    ``entry_um``, ``worst_deg``, ``worst_um``, ``tol_um``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(11, 5), dpi=90)
    ph = profile["phi_deg"]
    for i, sec in enumerate(profile["sections"]):
        lab = "" if sec["z"] is None else f", z = {sec['z']:g} mm"
        c = f"C{i}"
        ax.plot(ph, sec["working_um"], color=c, lw=1.3, label=f"working flank{lab}")
        ax.plot(ph, sec["nonworking_um"], color=c, lw=1.0, ls="--", label=f"non-working flank{lab}")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhspan(-profile["tol_um"], profile["tol_um"], color="0.85", zorder=0, label="contact tolerance")
    if np.isfinite(profile.get("entry_um", np.nan)):
        ax.plot([profile["entry_deg"]], [profile["entry_um"]], "v", color="tab:green", ms=9, label=f"entry gap {profile['entry_um']:.2f} um")
    ax.plot([profile["worst_deg"]], [profile["worst_um"]], "o", color="tab:red", ms=8, label=f"minimum {profile['worst_um']:.2f} um")
    lo = min(np.nanmin(s["working_um"]) for s in profile["sections"])
    lo = min(lo, np.nanmin([np.nanmin(s["nonworking_um"]) for s in profile["sections"]]))
    ax.set_ylim(min(lo * 1.15, -5.0), max(150.0, 0.0))
    ax.set_xlabel("tooth angle from the generator major axis, deg")
    ax.set_ylabel("clearance, um (negative: penetration depth)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper right")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def clearance_vs_angle_png(angles_deg: np.ndarray, working_um: np.ndarray, nonworking_um: np.ndarray, tol_um: float, title: str) -> bytes:
    """Smallest clearance over all teeth against the generator angle, per flank."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(11, 4), dpi=90)
    ax.plot(angles_deg, working_um, lw=1.0, label="working flank")
    ax.plot(angles_deg, nonworking_um, lw=1.0, ls="--", label="non-working flank")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhspan(-tol_um, tol_um, color="0.85", zorder=0, label="contact tolerance")
    ax.set_xlabel("generator angle, deg")
    ax.set_ylabel("smallest clearance over the teeth, um")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def tightest_spot_png(flex_teeth: np.ndarray, labels, rigid_teeth: np.ndarray, overlap, title: str) -> bytes:
    """The teeth around the tightest spot, unrolled about the worst tooth: flexspline (blue), rigid (grey), overlaps (red)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    centre = flex_teeth[len(flex_teeth) // 2].mean(axis=0)
    a_ref = float(np.arctan2(centre[1], centre[0]))
    r_ref = float(np.hypot(*centre))
    fig, axs = plt.subplots(1, 2, figsize=(13, 5.2), dpi=90)
    for ax, zoom in zip(axs, (False, True)):
        for t in rigid_teeth:
            ax.add_patch(Polygon(_unroll(t, r_ref, a_ref), closed=True, fc="0.8", ec="0.3", lw=0.6))
        for t, lab in zip(flex_teeth, labels):
            u = _unroll(t, r_ref, a_ref)
            ax.add_patch(Polygon(u, closed=True, fc="tab:blue", alpha=0.4, ec="tab:blue", lw=0.7))
            if not zoom:
                ax.text(u[:, 0].mean(), u[:, 1].max() + 0.05, lab, ha="center", fontsize=7, color="tab:blue")
        for poly in overlap:
            ax.add_patch(Polygon(_unroll(poly, r_ref, a_ref), closed=True, fc="tab:red", ec="tab:red", lw=0.8, alpha=0.9))
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.set_xlabel("arc length from the tooth, mm")
        ax.set_ylabel("radius - r, mm")
        ax.grid(alpha=0.25)
    allu = np.vstack([_unroll(t, r_ref, a_ref) for t in flex_teeth])
    axs[0].set_xlim(allu[:, 0].min() - 1, allu[:, 0].max() + 1)
    axs[0].set_ylim(allu[:, 1].min() - 0.3, allu[:, 1].max() + 0.8)
    mid = _unroll(flex_teeth[len(flex_teeth) // 2], r_ref, a_ref)
    if overlap:
        o = np.vstack([_unroll(p, r_ref, a_ref) for p in overlap])
        cx, cy = o.mean(axis=0)
        span = max(0.15, 0.6 * np.ptp(o, axis=0).max())
    else:
        cx, cy = mid.mean(axis=0)
        span = 0.8
    axs[1].set_xlim(cx - span, cx + span)
    axs[1].set_ylim(cy - span, cy + span)
    axs[1].set_title("close-up", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
