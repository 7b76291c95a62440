"""PNG pictures of a drive: deformed assembly, clearance profile and ripple, tightest spot, generator velocities."""

from __future__ import annotations

from math import ceil, pi

import numpy as np

from .mpl import png_bytes, pyplot

__all__ = [
    "DPI",
    "MIN_FONT_PT",
    "assembly_figure",
    "assembly_png",
    "clearance_profile_figure",
    "clearance_profile_png",
    "clearance_vs_angle_figure",
    "clearance_vs_angle_png",
    "closeup_limits",
    "profile_y_range",
    "tightest_spot_figure",
    "tightest_spot_png",
    "velocities_figure",
    "velocities_png",
    "fold_breaks",
]

#: resolution of every PNG, dots per inch (90 made 6.5 pt labels a few pixels high)
DPI = 150
#: smallest font anywhere in a picture, points (tick labels, legends, tooth labels)
MIN_FONT_PT = 8.0
_LEGEND_PT = 8.5
#: least margin above and below the curves against generator angle, um: an exact ripple of a few nm stays readable,
#: the view at most twice the ripple or 0.011 um
VS_ANGLE_MIN_PAD_UM = 0.0025
# height of one unrolled close-up strip, inches: below ~1 in the teeth of a
# large drive (D3, 300 teeth) turn into a hatch pattern
_STRIP_MIN_IN = 1.15
_STRIP_WIDTH_IN = 10.5


_pyplot = pyplot


def _png(fig) -> bytes:
    """Render a figure to PNG bytes at :data:`DPI` and release it."""
    return png_bytes(fig, dpi=DPI)


def _unroll(pts: np.ndarray, r_ref: float, a_ref: float) -> np.ndarray:
    """Polar -> (arc length at r_ref from angle a_ref, radius - r_ref), mm: radial gaps stay true."""
    ang = np.arctan2(pts[..., 1], pts[..., 0]) - a_ref
    ang = (ang + pi) % (2 * pi) - pi
    return np.stack([r_ref * ang, np.hypot(pts[..., 0], pts[..., 1]) - r_ref], axis=-1)


def legend_outside(ax, **kw):
    """A legend to the right of the axes, where it cannot cover a curve."""
    return ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=_LEGEND_PT, **kw)


# ---------------------------------------------------------------- deformed assembly


def _axis_label_pos(angle: float, radius: float):
    """Text position and alignment for an axis label beyond ``radius`` on the ray at ``angle``, facing outward."""
    c, s = np.cos(angle), np.sin(angle)
    ha = "left" if c > 0.25 else ("right" if c < -0.25 else "center")
    va = "bottom" if s > 0.25 else ("top" if s < -0.25 else "center")
    return radius * c, radius * s, ha, va


def _strip_rows(x_total_mm: float, y_span_mm: float) -> int:
    """Strips needed so that each, drawn at true scale over the strip width, is at least :data:`_STRIP_MIN_IN` high."""
    per_row = _STRIP_WIDTH_IN * y_span_mm / _STRIP_MIN_IN
    return int(min(12, max(1, ceil(x_total_mm / per_row - 1e-9))))


def _schematic(ax0, scene: dict) -> None:
    """The whole drive, schematic: the neutral line with its deformation exaggerated (at true scale W0 is ~1 % of the
    radius and the oval cannot be seen), the axes named, and the legend of the whole figure beneath."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    a = scene["major_axis"]
    r_m, w0 = scene["r_m"], abs(scene["w0"])
    k = max(1.0, round(0.12 * r_m / w0))
    t = np.linspace(0, 2 * pi, 721)
    ro_r = scene["rigid_rim_radius"]
    ax0.plot(ro_r * np.cos(t), ro_r * np.sin(t), color="0.3", lw=0.8, label="rigid gear rim")
    ax0.plot(r_m * np.cos(t), r_m * np.sin(t), color="0.6", lw=0.8, ls=":", label="undeformed neutral line")
    pn = scene["neutral_phi"]
    rr = r_m + k * scene["neutral_w"]
    ax0.plot(rr * np.cos(pn), rr * np.sin(pn), color="tab:blue", lw=1.6, label=f"deformed neutral line (w x {k:g})")
    # axis lines end just outside every curve and their names sit beyond, facing outward
    r_out = 1.03 * max(ro_r, float(np.max(rr)), r_m)
    for s_, col, name in ((0.0, "tab:red", "major axis"), (pi / scene["waves"], "tab:green", "minor axis")):
        aa = a + s_
        ax0.plot(
            [-r_out * np.cos(aa), r_out * np.cos(aa)],
            [-r_out * np.sin(aa), r_out * np.sin(aa)],
            color=col,
            lw=1.0,
            ls="--",
        )
        x, y, ha, va = _axis_label_pos(aa, 1.05 * r_out)
        ax0.text(x, y, name, color=col, fontsize=9, ha=ha, va=va)
    lim = 1.45 * r_out
    ax0.set_xlim(-lim, lim)
    ax0.set_ylim(-lim, lim)
    ax0.set_aspect("equal")
    ax0.set_title(f"whole drive, schematic:\ndeformation exaggerated x{k:g}", fontsize=10)
    hand, _ = ax0.get_legend_handles_labels()
    hand += [
        Patch(fc="0.80", ec="0.3", label="rigid gear (close-ups, true shape and scale)"),
        Patch(fc="tab:blue", alpha=0.45, ec="tab:blue", label="flexspline teeth (close-ups)"),
        Line2D([], [], ls="", label="numbers above each close-up: the flexspline\ntooth's angle from the major axis"),
    ]
    ax0.legend(handles=hand, fontsize=_LEGEND_PT, loc="upper center", bbox_to_anchor=(0.5, 0.0))
    ax0.axis("off")


def assembly_figure(scene: dict, title: str, entry_deg: float = 50.0, rows: int | None = None):
    """A deformed state as a matplotlib figure (see :func:`assembly_png`)."""
    plt = _pyplot()
    from matplotlib.patches import Polygon

    r_ref, sgn, a = scene["r_ref"], scene["entry_sign"], scene["major_axis"]
    span = np.deg2rad(entry_deg)
    lo_ang = -np.deg2rad(4.0)
    y_lo, y_hi = scene["y_range"]
    if rows is None:
        rows = _strip_rows(r_ref * (span - lo_ang), y_hi - y_lo)
    x_row = r_ref * (span - lo_ang) / rows
    strip_h = _STRIP_WIDTH_IN * (y_hi - y_lo) / x_row  # true scale
    fig_h = max(7.0, rows * (strip_h + 0.8) + 1.3)
    fig = plt.figure(figsize=(16, fig_h), layout="constrained", dpi=DPI)
    gs = fig.add_gridspec(rows, 2, width_ratios=[1, 2.6])

    _schematic(fig.add_subplot(gs[:, 0]), scene)

    # close-up: unrolled strips from just behind the major axis to the entry side
    teeth, phi = scene["flex_teeth"], scene["flex_phi"]
    phi_w = (phi + pi) % (2 * pi) - pi
    rig_u = _unroll(scene["rigid_outline"], r_ref, a)
    rig_u = np.roll(rig_u, -int(np.argmin(rig_u[:, 0])), axis=0)  # start at the wrap (opposite the window)
    edges = np.linspace(lo_ang, span, rows + 1)
    out = scene["rigid_outward"]
    for i in range(rows):
        ax = fig.add_subplot(gs[i, 1])
        lo, hi = edges[i], edges[i + 1]
        x_lo, x_hi = sorted((sgn * r_ref * lo, sgn * r_ref * hi))
        pad = 0.6 * scene["module"]
        sel = (rig_u[:, 0] > x_lo - 3 * pad) & (rig_u[:, 0] < x_hi + 3 * pad)
        if sel.any():
            # polygon of the rigid teeth in this strip, closed through the rim side
            seg = rig_u[sel]
            yb = seg[:, 1].max() + 0.5 * scene["module"] if out else seg[:, 1].min() - 0.5 * scene["module"]
            poly = np.vstack([seg, [[seg[-1, 0], yb], [seg[0, 0], yb]]])
            ax.add_patch(Polygon(poly, closed=True, fc="0.80", ec="0.3", lw=0.6))
        cxs, labs = [], []
        for j in np.nonzero((sgn * phi_w >= lo - 0.02) & (sgn * phi_w <= hi + 0.02))[0]:
            tu = _unroll(teeth[j], r_ref, a)
            ax.add_patch(Polygon(tu, closed=True, fc="tab:blue", alpha=0.45, ec="tab:blue", lw=0.6))
            cx = tu[np.argmax(tu[:, 1]) if out else np.argmin(tu[:, 1]), 0]
            if x_lo - pad <= cx <= x_hi + pad:
                cxs.append(cx)
                labs.append(f"{np.rad2deg(phi_w[j]):.1f}°")
        ax.set_xlim(x_lo - pad, x_hi + pad)
        ax.set_ylim(y_lo, y_hi)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=MIN_FONT_PT)
        ax.set_ylabel("R - r_ref, mm", fontsize=MIN_FONT_PT)
        # tooth angles outside the drawing, above each flexspline tooth: nothing covers a tooth
        top = ax.secondary_xaxis("top")
        top.set_xticks(cxs, labels=labs)
        top.tick_params(labelsize=MIN_FONT_PT, colors="tab:blue", length=3)
        if i == 0:
            top.set_xlabel("flexspline tooth angle from the major axis", fontsize=9, color="tab:blue")
        if i == rows - 1:
            ax.set_xlabel(
                f"arc length at r_ref = {r_ref:.2f} mm from the major axis, mm (entry side {'+' if sgn > 0 else '-'})",
                fontsize=9,
            )
    fig.suptitle(title, fontsize=11)
    return fig


def assembly_png(scene: dict, title: str, entry_deg: float = 50.0, rows: int | None = None) -> bytes:
    """Render a deformed state to PNG bytes.

    Parameters
    ----------
    scene : dict
        ``flex_teeth`` (K, N, 2) placed flexspline teeth (rigid frame drawn),
        ``flex_phi`` (K,) their angles from the major axis (rad),
        ``rigid_outline`` (M, 2), ``rigid_rim_radius``, ``major_axis`` (rad,
        drawing frame), ``entry_sign`` (+1: teeth enter at positive phi),
        ``r_ref`` radius for the unrolled view, ``y_range`` its radial window
        (mm from r_ref), ``r_m``, ``w0``, ``neutral_phi``, ``neutral_w``,
        ``waves``, ``module``, ``rigid_outward``.
    title : str
    entry_deg : float
        Close-up span from the major axis toward the entry side, degrees.
    rows : int, optional
        Strips of the close-up; by default as many as keep each strip, at
        true scale, at least ~1.15 in high.
    """
    return _png(assembly_figure(scene, title, entry_deg, rows))


# ---------------------------------------------------------------- clearance profile


def fold_breaks(working: np.ndarray, nonworking: np.ndarray, rel: float = 0.02) -> np.ndarray:
    """Indices ``i`` where the two flank curves exchange values between samples ``i`` and ``i + 1``.

    Where a flexspline tooth passes a rigid tooth tip to tip (at the minor
    axis when the teeth are centred in the rigid spaces at the major axis),
    the rigid tooth it faces changes from one flank's side to the other's:
    the per-flank clearance jumps while the geometry does not. Such a step
    shows as ``(w, n) -> (~n, ~w)`` with a jump larger than the exchange error.
    A lone step of one curve 200 times its median step is the same kind of
    change of the facing rigid tooth (a continuous curve cannot step so).

    Parameters
    ----------
    working, nonworking : (P,) float
        Clearance of each flank at consecutive tooth angles (any unit).
    rel : float
        Largest exchange error as a fraction of the jump.

    Examples
    --------
    >>> fold_breaks(np.array([109.0, 1985.0, 1982.0]), np.array([1988.0, 109.1, 109.0])).tolist()
    [0]
    """
    w, n = np.asarray(working, float), np.asarray(nonworking, float)
    jump = np.abs(np.diff(w)) + np.abs(np.diff(n))
    miss = np.abs(w[:-1] - n[1:]) + np.abs(n[:-1] - w[1:])
    with np.errstate(invalid="ignore"):
        typical = np.nanmedian(jump) if jump.size else 0.0
        hit = (miss < rel * jump) & (jump > 50.0 * max(typical, 1e-12))
        # a clearance to one fixed rigid tooth moves continuously with the tooth, so a lone
        # step of one curve far beyond its typical step is its nearest rigid tooth changing
        # (teeth deformed by more than a pitch, e.g. W0 = 2 m): a break too, not a jump
        for c in (w, n):
            d = np.abs(np.diff(c))
            hit |= d > 200.0 * max(np.nanmedian(d) if d.size else 0.0, 1e-12)
    return np.nonzero(hit)[0]


def _broken(x: np.ndarray, y: np.ndarray, breaks: np.ndarray):
    """x, y with a NaN after each break index, so the line is not drawn across it."""
    if not len(breaks):
        return x, y
    return np.insert(x, breaks + 1, np.nan), np.insert(np.asarray(y, float), breaks + 1, np.nan)


def profile_y_range(profile: dict) -> tuple[float, float]:
    """The passage profile's y range, um, in the PNG and on the page: from the deepest point (or the contact band)
    to above the highest marker (entry gaps, the minimum) and at least 150 um; the curves rise to millimetres out of
    mesh, and showing that would flatten the engagement."""
    tol = profile["tol_um"]
    lows = [
        np.nanmin(np.asarray(sec[k], float)) for sec in profile["sections"] for k in ("working_um", "nonworking_um")
    ]
    marks = [profile["worst_um"], tol] + [
        profile[k] for k in ("entry_um", "entry2_um") if np.isfinite(profile.get(k, np.nan))
    ]
    lo = min(min(lows), profile["worst_um"], -tol)
    hi = max(marks)
    top = max(150.0, hi + 0.15 * (hi - lo))
    return lo - 0.08 * (top - lo), top


def clearance_profile_figure(profile: dict, title: str):
    """The per-tooth clearance profile as a matplotlib figure (see :func:`clearance_profile_png`)."""
    plt = _pyplot()
    from matplotlib.lines import Line2D

    fig, ax = plt.subplots(figsize=(13, 5.6), layout="constrained", dpi=DPI)
    ph = np.asarray(profile["phi_deg"], float)
    tol = profile["tol_um"]
    fold_x = []
    for i, sec in enumerate(profile["sections"]):
        lab = "" if sec["z"] is None else f", z = {sec['z']:g} mm"
        c = f"C{i}"
        w, n = np.asarray(sec["working_um"], float), np.asarray(sec["nonworking_um"], float)
        br = fold_breaks(w, n)
        fold_x += [(0.5 * (ph[j] + ph[j + 1]), min(w[j], n[j])) for j in br]
        ax.plot(*_broken(ph, w, br), color=c, lw=1.4, label=f"working flank{lab}")
        ax.plot(*_broken(ph, n, br), color=c, lw=1.0, ls="--", label=f"non-working flank{lab}")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axhspan(-tol, tol, color="0.85", zorder=0, label=f"contact tolerance +-{tol:g} um")
    if np.isfinite(profile.get("entry_um", np.nan)):
        ax.plot(
            [profile["entry_deg"]],
            [profile["entry_um"]],
            "v",
            color="tab:green",
            ms=9,
            zorder=5,
            label=profile.get("entry_label", "entry gap")
            + f" {profile['entry_um']:.2f} um at {profile['entry_deg']:+.1f}°",
        )
    if np.isfinite(profile.get("entry2_um", np.nan)):
        ax.plot(
            [profile["entry2_deg"]],
            [profile["entry2_um"]],
            "v",
            color="tab:purple",
            ms=9,
            zorder=5,
            label=profile.get("entry2_label", "entry gap")
            + f"\n{profile['entry2_um']:.2f} um at {profile['entry2_deg']:+.1f}°",
        )
    ax.plot(
        [profile["worst_deg"]],
        [profile["worst_um"]],
        "o",
        color="tab:red",
        ms=8,
        zorder=5,
        label=profile.get("worst_label", "minimum") + f" {profile['worst_um']:.2f} um at {profile['worst_deg']:+.1f}°",
    )
    bottom, top = profile_y_range(profile)
    ax.set_ylim(bottom, top)
    half = max(abs(ph[0]), abs(ph[-1]))
    ax.set_xlim(ph[0], ph[-1])
    ticks = np.arange(-np.floor(half / 15) * 15, half + 1e-9, 15.0)
    ticks = np.unique(np.concatenate([ticks, [ph[0], ph[-1]]]))
    names = {0.0: "\nmajor axis"}
    ax.set_xticks(
        ticks,
        labels=[f"{t:g}" + (names.get(round(t, 6), "") if abs(t) < half - 1e-6 else "\nminor axis") for t in ticks],
    )
    # a break is worth a word only where the exchanged values are on the scale
    fold_x = sorted({round(float(x), 1) for x, y in fold_x if y <= top})
    for fx in fold_x:
        ax.axvline(fx, color="0.4", lw=1.0, ls=":")
    handles, _ = ax.get_legend_handles_labels()
    if fold_x:
        handles.append(
            Line2D(
                [],
                [],
                color="0.4",
                lw=1.0,
                ls=":",
                label="break at {}°: the tooth stands tip to tip with\n"
                "a rigid tooth, which passes from one flank's side\n"
                "to the other's: the two curves exchange values\n"
                "there (not a jump in clearance)".format(", ".join(f"{x:+.1f}" for x in fold_x)),
            )
        )
    handles.append(Line2D([], [], ls="", label=f"curves above {top:.0f} um not shown\n(teeth out of mesh)"))
    legend_outside(ax, handles=handles)
    ax.tick_params(labelsize=9)
    ax.set_xlabel("tooth angle from the generator major axis, deg", fontsize=10)
    ax.set_ylabel("clearance, um (negative: penetration depth)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    return fig


def clearance_profile_png(profile: dict, title: str) -> bytes:
    """Per-tooth clearance against the tooth's angle from the major axis, per flank and section, as PNG bytes.

    ``profile``: ``phi_deg`` (P,), ``sections`` list of dicts with ``z``,
    ``working_um``, ``nonworking_um`` (P,) arrays; ``entry_deg``,
    ``entry_um``, ``worst_deg``, ``worst_um``, ``tol_um``. Both markers and
    the contact band are always inside the y range; where the flank curves
    exchange values (:func:`fold_breaks`) the lines break and the legend
    says why.
    """
    return _png(clearance_profile_figure(profile, title))


# ---------------------------------------------------------------- clearance against generator angle


def clearance_vs_angle_figure(angles_deg, working_um, nonworking_um, tol_um: float, title: str, reported_um=None):
    """The ripple of the smallest clearance as a matplotlib figure (see :func:`clearance_vs_angle_png`)."""
    plt = _pyplot()

    fig, axs = plt.subplots(2, 1, figsize=(13, 6.4), sharex=True, layout="constrained", dpi=DPI)
    ang = np.asarray(angles_deg, float)
    for ax, y, name, style in (
        (axs[0], working_um, "working flank", "-"),
        (axs[1], nonworking_um, "non-working flank", "--"),
    ):
        y = np.asarray(y, float)
        fin = y[np.isfinite(y)]
        y_min, y_max = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 0.0)
        rip = y_max - y_min
        ax.plot(
            ang, y, lw=1.2, ls=style, color="C0" if style == "-" else "C1", label=f"smallest over the teeth, {name}"
        )
        # scaled to the ripple (the reason for this picture), not from zero
        pad = max(0.12 * rip, VS_ANGLE_MIN_PAD_UM)
        lo, hi = y_min - pad, y_max + pad
        shown = reported_um is not None and lo <= reported_um <= hi
        if shown:
            # the audit's exact minimum where it is reported: the curve reaches it (a tooth at the spot) or not
            ax.axhline(reported_um, color="tab:red", lw=1.0, ls=":", label=f"the audit's minimum {reported_um:.3f} um")
        ax.set_ylim(lo, hi)
        ax.ticklabel_format(axis="y", useOffset=False)
        where = "0 um above this scale" if hi <= 0.0 else ("0 um below this scale" if lo >= 0.0 else "0 um: black line")
        if reported_um is not None and not shown:
            where += f"; the audit's minimum {reported_um:.3f} um {'below' if reported_um < lo else 'above'} this scale"
            where += (
                " (the curve's samples are 0.1 deg of tooth angle apart)" if abs(reported_um - y_min) < 0.05 else ""
            )
        if hi > -tol_um and lo < tol_um:
            ax.axhspan(-tol_um, tol_um, color="0.85", zorder=0)
            where += f"; grey band: contact within +-{tol_um:g} um"
        if lo < 0.0 < hi:
            ax.axhline(0.0, color="k", lw=0.8)
        ax.set_title(
            f"{name}: {y_min:.3f} to {y_max:.3f} um, ripple {rip:.3f} um peak to peak ({where})",
            fontsize=9.5,
            loc="left",
        )
        ax.set_ylabel("smallest clearance, um", fontsize=9.5)
        ax.tick_params(labelsize=9)
        ax.grid(alpha=0.3)
        legend_outside(ax)
    axs[1].set_xlabel("generator angle, deg", fontsize=10)
    fig.suptitle(
        title
        + "\n(read off the per-tooth profile, on the exact curves near its minimum; the audit's minimum is exact)",
        fontsize=10,
    )
    return fig


def clearance_vs_angle_png(
    angles_deg: np.ndarray,
    working_um: np.ndarray,
    nonworking_um: np.ndarray,
    tol_um: float,
    title: str,
    reported_um: float | None = None,
) -> bytes:
    """Smallest clearance over all teeth against the generator angle, one panel per flank, as PNG bytes.

    Each panel's y range is the curve's own range plus a margin, stated in
    its title with the peak-to-peak ripple and where zero lies; the audit's
    minimum ``reported_um`` is drawn where it lies near that range (else the
    title says where it is).
    """
    return _png(clearance_vs_angle_figure(angles_deg, working_um, nonworking_um, tol_um, title, reported_um))


# ---------------------------------------------------------------- tightest spot


def tightest_spot_figure(flex_teeth: np.ndarray, labels, rigid_teeth: np.ndarray, overlap, title: str, spot=None):
    """The tightest spot as a matplotlib figure (see :func:`tightest_spot_png`)."""
    plt = _pyplot()
    from matplotlib.patches import Polygon

    centre = flex_teeth[len(flex_teeth) // 2].mean(axis=0)
    a_ref = float(np.arctan2(centre[1], centre[0]))
    r_ref = float(np.hypot(*centre))
    fig, axs = plt.subplots(1, 2, figsize=(15, 5.0), width_ratios=[2.3, 1], layout="constrained", dpi=DPI)
    for ax, zoom in zip(axs, (False, True)):
        for t in rigid_teeth:
            ax.add_patch(Polygon(_unroll(t, r_ref, a_ref), closed=True, fc="0.8", ec="0.3", lw=0.6))
        for t in flex_teeth:
            ax.add_patch(
                Polygon(_unroll(t, r_ref, a_ref), closed=True, fc="tab:blue", alpha=0.4, ec="tab:blue", lw=0.7)
            )
        for poly in overlap:
            ax.add_patch(
                Polygon(_unroll(poly, r_ref, a_ref), closed=True, fc="tab:red", ec="tab:red", lw=0.8, alpha=0.9)
            )
        ax.set_aspect("equal")
        ax.set_xlabel("arc length from the tooth, mm", fontsize=9.5)
        ax.set_ylabel("radius - r, mm", fontsize=9.5)
        ax.tick_params(labelsize=9)
        ax.grid(alpha=0.25)
    allu = np.vstack([_unroll(t, r_ref, a_ref) for t in flex_teeth])
    x0, x1 = allu[:, 0].min() - 1, allu[:, 0].max() + 1
    axs[0].set_xlim(x0, x1)
    # both gears' teeth in view (the rigid ones lie below the flexspline's on an external drive)
    if len(rigid_teeth):
        rig = np.vstack([_unroll(t, r_ref, a_ref) for t in rigid_teeth])
        allu = np.vstack([allu, rig[(rig[:, 0] > x0) & (rig[:, 0] < x1)]])
    axs[0].set_ylim(allu[:, 1].min() - 0.2, allu[:, 1].max() + 0.2)
    # tooth names above the drawing, not over the rigid teeth
    tops = [_unroll(t, r_ref, a_ref) for t in flex_teeth]
    top = axs[0].secondary_xaxis("top")
    top.set_xticks([float(u[:, 0].mean()) for u in tops], labels=list(labels))
    top.tick_params(labelsize=MIN_FONT_PT, colors="tab:blue", length=3)
    top.set_xlabel(
        "flexspline tooth angle from the major axis (red: overlap of the worst tooth)", fontsize=9, color="tab:blue"
    )
    mid = _unroll(flex_teeth[len(flex_teeth) // 2], r_ref, a_ref)
    ov = np.vstack([_unroll(p, r_ref, a_ref) for p in overlap]) if overlap else None
    ends = None if spot is None else _unroll(np.stack([spot["flex"], spot["rigid"]]), r_ref, a_ref)
    (cx0, cx1), (cy0, cy1) = closeup_limits(ends, ov, mid)
    axs[1].set_xlim(cx0, cx1)
    axs[1].set_ylim(cy0, cy1)
    if ends is not None:
        _mark_spot(axs, ends, spot.get("label", f"tightest spot: {spot['um']:.2f} um"))
    axs[1].set_title(
        "close-up of the tightest spot" if ends is not None else "close-up of the worst tooth", fontsize=9.5
    )
    fig.suptitle(title, fontsize=10)
    return fig


def closeup_limits(ends, overlap, tooth) -> tuple[tuple[float, float], tuple[float, float]]:
    """The close-up's ``(x limits, y limits)``, mm in the unrolled frame: centred on the tightest spot (``ends``, the
    gap's two ends, ``(2, 2)``), wide enough for six times its gap and every overlap, the ends at least a fifth of the
    view from its edges; without a spot, on the overlaps or else the worst tooth (``tooth``, its outline)."""
    if ends is not None:
        ends = np.asarray(ends, float)
        cx, cy = ends.mean(axis=0)
        half = float(np.clip(6.0 * np.ptp(ends, axis=0).max(), 0.05, 0.8))
        if overlap is not None:
            half = max(half, 0.6 * float(np.ptp(overlap, axis=0).max()))
        half = max(half, float(np.abs(ends - (cx, cy)).max()) / 0.6)  # the ends inside, with a margin
    elif overlap is not None:
        cx, cy = overlap.mean(axis=0)
        half = max(0.15, 0.6 * float(np.ptp(overlap, axis=0).max()))
    else:
        cx, cy = np.asarray(tooth, float).mean(axis=0)
        half = 0.8
    return (cx - half, cx + half), (cy - half, cy + half)


def _mark_spot(axs, ends, label: str) -> None:
    """The tightest spot in both panels: a ring in the overview, the gap's two ends joined in the close-up, its
    figure in the close-up's legend."""
    mid = ends.mean(axis=0)
    axs[0].plot(*mid, "o", ms=11, mfc="none", mec="tab:red", mew=1.6, zorder=5)
    axs[1].plot(ends[:, 0], ends[:, 1], "-", color="tab:red", lw=1.6, zorder=5)
    axs[1].plot(ends[:, 0], ends[:, 1], "o", ms=4.5, color="tab:red", zorder=6, label=label)
    axs[1].legend(loc="lower left", fontsize=_LEGEND_PT, framealpha=0.9)


def tightest_spot_png(flex_teeth: np.ndarray, labels, rigid_teeth: np.ndarray, overlap, title: str, spot=None) -> bytes:
    """The teeth around the tightest spot, unrolled about the worst tooth: flexspline (blue), rigid (grey), overlaps
    (red); ``spot`` (:func:`wgcad.export.pictures.audit.tightest_points`, with a ``label``): the close-up framed on
    it and the spot marked."""
    return _png(tightest_spot_figure(flex_teeth, labels, rigid_teeth, overlap, title, spot))


# ---------------------------------------------------------------- external ring generator velocities


def velocities_figure(vel, title: str):
    """The ring generator's velocity fields as a matplotlib figure (see :func:`velocities_png`)."""
    plt = _pyplot()

    ph = np.rad2deg(vel.phi)
    fig, axs = plt.subplots(2, 2, figsize=(15, 9), sharex=True, layout="constrained", dpi=DPI)
    (a_rad, a_tan), (a_sl, a_th) = axs
    a_rad.plot(
        ph,
        vel.V_w,
        color="C0",
        lw=1.6,
        label="V_w = dw/dt: radial speed of the neutral line\n(= V_wK of the outer surface K: w_K = w + h_c/2)",
    )
    a_rad.plot(
        ph,
        vel.V_dw,
        color="C1",
        lw=1.3,
        ls="--",
        label="V_dw = a_w omega_h sin(phi):\nradial component of the washer speed",
    )
    a_rad.set_title("radial speeds", fontsize=10)
    dv = float(np.max(np.abs(vel.V_vK - vel.V_v)))
    a_tan.plot(ph, vel.V_v, color="C2", lw=2.6, alpha=0.6, label="V_v = dv/dt: tangential speed of the neutral line")
    a_tan.plot(
        ph,
        vel.V_vK,
        color="k",
        lw=1.0,
        ls="--",
        label=f"V_vK = V_v + (h_c/2) dtheta/dt: tangential speed of\nthe outer surface K (at most {dv:.3g} mm/s from V_v)",
    )
    a_tan.plot(
        ph,
        vel.V_dv,
        color="C3",
        lw=1.3,
        ls="-.",
        label="V_dv = a_w omega_h cos(phi):\ntangential component of the washer speed",
    )
    a_tan.set_title("tangential speeds", fontsize=10)
    a_sl.plot(ph, vel.V_sl, color="C4", lw=1.6, label="V_sl = V_d - V_v: sliding speed\nbetween washer and flexspline")
    a_sl.plot(ph, vel.V_d, color="0.4", lw=1.2, ls=":", label="V_d = omega_h a_w: speed of every washer point")
    a_sl.set_title("sliding at the washers", fontsize=10)
    a_th.plot(ph, vel.dtheta_dt, color="k", lw=1.4, label="dtheta/dt: angular speed of the\nrim cross-section")
    a_th.set_title("rotation of the rim cross-section", fontsize=10)
    for ax in (a_rad, a_tan, a_sl):
        ax.set_ylabel("mm/s", fontsize=10)
    a_th.set_ylabel("rad/s", fontsize=10)
    for ax in axs[1]:
        ax.set_xlabel("phi, deg from the washer contact (major axis)", fontsize=10)
    for ax in axs.flat:
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=9)
        ax.legend(
            fontsize=_LEGEND_PT, loc="upper center", bbox_to_anchor=(0.5, -0.12 if ax in axs[1] else -0.04), ncol=1
        )
    fig.suptitle(title, fontsize=11)
    return fig


def velocities_png(vel, title: str) -> bytes:
    """Velocities of the external ring generator (docs/models.md 3.5) as PNG bytes.

    Parameters
    ----------
    vel : wgcad.kinematics.RingVelocities
    title : str
    """
    return _png(velocities_figure(vel, title))
