"""Pictures a person can read: every template's PNGs, drawn by the CLI, checked the way a designer looks at them."""

import re

import numpy as np
import pytest
from conftest import TEMPLATES
from PIL import Image

import wgcad.export.pictures.drive as F
import wgcad.export.pictures.imperfect as IF
from wgcad.cli import main

NAMES = sorted(p.stem for p in TEMPLATES.glob("*.toml"))
KINDS = ("assembly", "clearance_profile", "clearance_vs_angle", "tightest_spot", "velocities", "entry_passages")
#: templates with [imperfections]: their vs_angle picture is every passage's entry gap (the mesh period is broken)
IMPERFECT = {"d2_imperfect"}
# D3 at 0 deg: the major axis is horizontal and its name sat on the neutral line
ANGLES = {"d3_external": "0,30"}


@pytest.fixture(scope="module")
def pictures(tmp_path_factory):
    """Run generate, audit --plot and kinematics on every template; keep every figure the CLI drew.

    Yields the output folder and ``{(template, kind): [Figure, ...]}``. The
    figures are the ones the PNGs were rendered from (same dpi, same layout).
    """
    import matplotlib.pyplot as plt

    out = tmp_path_factory.mktemp("pictures")
    figs = {}
    current = {}
    close = plt.close
    with pytest.MonkeyPatch.context() as mp:
        # keep the figures open after rendering: their canvas and renderer are the PNG's
        mp.setattr(plt, "close", lambda *a, **k: None)
        mp.setitem(plt.rcParams, "figure.max_open_warning", 0)
        for kind in KINDS:
            mod = IF if kind == "entry_passages" else F
            orig = getattr(mod, f"{kind}_figure")

            def record(*a, _orig=orig, _kind=kind, **k):
                fig = _orig(*a, **k)
                figs.setdefault((current["name"], _kind), []).append(fig)
                return fig

            mp.setattr(mod, f"{kind}_figure", record)
        for name in NAMES:
            current["name"] = name
            t = str(TEMPLATES / f"{name}.toml")
            angles = ANGLES.get(name, "30")
            assert (
                main(["generate", t, "--no-stl", "--generator-angle", angles, "--out", str(out / name), "--quiet"]) == 0
            )
            # a coarse audit: the pictures' curves come from the per-tooth profile, not from the audit's step
            assert main(["audit", t, "--step-deg", "6", "--plot", str(out / name / name), "--quiet"]) in (0, 1)
            if name == "d3_external":
                assert main(["kinematics", t, "--out", str(out / name)]) == 0
    yield out, figs
    for fl in figs.values():
        for fig in fl:
            close(fig)


def _all(figs, kind=None):
    for (name, k), fl in sorted(figs.items()):
        if kind is None or k == kind:
            for fig in fl:
                yield f"{name}:{k}", fig


def _display_points(line, n_sub: int = 40) -> np.ndarray:
    """A line's vertices in display pixels, each segment subdivided (a 2-point line crosses a box between its ends)."""
    xy = np.asarray(line.get_xydata(), float)
    xy = xy[np.isfinite(xy).all(axis=1)]
    if len(xy) == 0:
        return np.zeros((0, 2))
    if len(xy) > 1:
        t = np.linspace(0.0, 1.0, n_sub, endpoint=False)
        seg = xy[:-1, None, :] + t[None, :, None] * (xy[1:] - xy[:-1])[:, None, :]
        xy = np.vstack([seg.reshape(-1, 2), xy[-1:]])
    return line.get_transform().transform(xy)


def _inside(pts: np.ndarray, bbox, shrink: float = 1.0) -> np.ndarray:
    return (
        (pts[:, 0] > bbox.x0 + shrink)
        & (pts[:, 0] < bbox.x1 - shrink)
        & (pts[:, 1] > bbox.y0 + shrink)
        & (pts[:, 1] < bbox.y1 - shrink)
    )


def test_every_template_writes_its_pictures(pictures):
    out, figs = pictures
    for name in NAMES:
        folder = out / name
        n_angles = len(ANGLES.get(name, "30").split(","))
        want = [f"{name}_profile.png", f"{name}_vs_angle.png", f"{name}_tightest.png"]
        if name == "d3_external":
            want.append(f"{name}_velocities.png")
        pngs = sorted(folder.glob(f"{name}_phi*.png"))
        assert len(pngs) == n_angles, (name, pngs)
        for p in pngs + [folder / w for w in want]:
            assert p.is_file(), p
            with Image.open(p) as im:
                im.verify()
            with Image.open(p) as im:
                # the PNG records the resolution it was drawn at
                assert min(im.info["dpi"]) >= F.DPI - 0.5, (p, im.info.get("dpi"))
                assert im.size[0] >= 1500, (p, im.size)
        assert len(figs[(name, "assembly")]) == n_angles
        vs = "entry_passages" if name in IMPERFECT else "clearance_vs_angle"
        for kind in ("clearance_profile", vs, "tightest_spot"):
            assert len(figs[(name, kind)]) == 1, (name, kind)
    assert len(figs[("d3_external", "velocities")]) == 1


def test_resolution_and_font_sizes(pictures):
    _, figs = pictures
    from matplotlib.text import Text

    assert F.DPI >= 150 and F.MIN_FONT_PT >= 8.0  # the floor this test holds every picture to
    small = []
    for key, fig in _all(figs):
        assert fig.dpi >= F.DPI, key
        for t in fig.findobj(Text):
            if t.get_visible() and t.get_text().strip() and t.get_fontsize() < F.MIN_FONT_PT - 1e-9:
                small.append((key, t.get_text()[:30], t.get_fontsize()))
    assert not small, small[:10]


def test_legends_do_not_cover_curves(pictures):
    _, figs = pictures
    covered = []
    for key, fig in _all(figs):
        r = fig.canvas.get_renderer()
        for ax in fig.axes:
            leg = ax.get_legend()
            if leg is None:
                continue
            lb = leg.get_window_extent(r)
            for other in fig.axes:
                ob = other.get_window_extent(r)
                for line in other.get_lines():
                    pts = _display_points(line)
                    pts = pts[_inside(pts, ob, 0.0)]  # only what the axes shows
                    hit = _inside(pts, lb)
                    if hit.any():
                        covered.append((key, line.get_label(), int(hit.sum())))
    assert not covered, covered[:10]


def test_profile_markers_and_contact_band_in_view(pictures):
    _, figs = pictures
    for key, fig in _all(figs, "clearance_profile"):
        ax = fig.axes[0]
        lo, hi = ax.get_ylim()
        margin = 0.02 * (hi - lo)  # a marker half off the edge is not seen
        marks = [ln for ln in ax.get_lines() if len(ln.get_ydata()) == 1]
        assert len(marks) >= 1, key
        for ln in marks:
            y = float(ln.get_ydata()[0])
            assert lo + margin <= y <= hi - margin, (key, ln.get_label(), y, (lo, hi))
        assert lo < 0.0 < hi, key


def test_d1_cycloidal_entry_gap_marker_is_shown(pictures):
    """The case of issue 13: a 205.6 um entry gap above a fixed 150 um ceiling."""
    _, figs = pictures
    fig = figs[("d1_cycloidal", "clearance_profile")][0]
    ax = fig.axes[0]
    entry = [ln for ln in ax.get_lines() if ln.get_label().startswith("entry gap")]
    assert len(entry) == 1
    y = float(entry[0].get_ydata()[0])
    assert y > 150.0  # the premise: the gap lies above the old fixed ceiling
    assert y < ax.get_ylim()[1]


def test_profile_curves_have_no_jumps(pictures):
    """Between two 0.1 deg samples no curve may jump by a fifth of its range: where the flank
    curves exchange values (tip to tip at the minor axis) the line must break instead."""
    _, figs = pictures
    for key, fig in _all(figs, "clearance_profile"):
        for ln in fig.axes[0].get_lines():
            y = np.asarray(ln.get_ydata(), float)
            if len(y) < 10:
                continue
            span = np.nanmax(y) - np.nanmin(y)
            step = np.abs(np.diff(y))  # NaN across a break: not a step
            assert np.nanmax(step) <= 0.2 * span, (key, ln.get_label(), np.nanmax(step), span)


def test_d3_fold_is_an_exchange_of_flanks_not_a_jump():
    """The premise of the legend's explanation, on the real D3 profile: at each break the two
    flank curves swap values, and the smaller of the two (what the geometry decides) is continuous."""
    from wgcad.clearance.engine import Scene, clearance_profile
    from wgcad.design import load_design
    from wgcad.drive import build_drive

    drive = build_drive(load_design(TEMPLATES / "d3_external.toml"))
    prof = clearance_profile(Scene(drive), [None])
    ph = np.rad2deg(prof["phi"])
    w, n = 1e3 * prof["sections"][0]["working"], 1e3 * prof["sections"][0]["nonworking"]
    br = F.fold_breaks(w, n)
    assert len(br) >= 1
    half = 180.0 / drive.design.drive.waves
    for i in br:
        jump = abs(w[i + 1] - w[i])
        assert jump > 1000.0  # a ~1.9 mm step of one flank's curve in 0.1 deg
        # within 0.2 deg of the minor axis, where the tooth stands tip to tip with a rigid tooth
        assert half - abs(ph[i]) <= 0.2 and half - abs(ph[i + 1]) <= 0.2, (ph[i], ph[i + 1])
        # the nearer rigid tooth stays as near: one 0.1 deg step changes it by << the jump (1 %)
        assert abs(min(w[i], n[i]) - min(w[i + 1], n[i + 1])) < 0.01 * jump


def test_fold_breaks_ignores_smooth_crossings():
    x = np.linspace(-1.0, 1.0, 401)
    w, n = 100 * x**2, 100 * (x - 0.3) ** 2  # curves that cross: no exchange of labels
    assert F.fold_breaks(w, n).size == 0
    # the same curves with their labels exchanged at x = 0 (and one of them far off)
    w3, n3 = np.where(x < 0, w + 1e3, n), np.where(x < 0, n, w + 1e3)
    assert F.fold_breaks(w3, n3).tolist() == [int(np.argmax(x >= 0)) - 1]


def test_vs_angle_panels_show_the_ripple(pictures):
    """Each flank's panel is scaled to its own ripple (not from 0 to the minimum, where it was a flat
    line) and its title states the range."""
    _, figs = pictures
    for key, fig in _all(figs, "clearance_vs_angle"):
        axs = [ax for ax in fig.axes if ax.get_lines()]
        assert len(axs) == 2, key
        for ax in axs:
            y = np.asarray(ax.get_lines()[0].get_ydata(), float)
            lo, hi = ax.get_ylim()
            rip = np.ptp(y)
            assert rip >= 0.5 * (hi - lo) or hi - lo <= 0.011, (key, rip, (lo, hi))
            nums = [float(v) for v in re.findall(r"-?\d+\.\d+", ax.get_title(loc="left"))]
            assert nums[:3] == pytest.approx([y.min(), y.max(), rip], abs=1.5e-3), (key, ax.get_title(loc="left"))


def test_assembly_labels_clear_of_the_drawing(pictures):
    """Tooth angles sit outside the close-ups (not over the rigid teeth), and no curve of the
    schematic runs through an axis name."""
    _, figs = pictures
    for key, fig in _all(figs, "assembly"):
        r = fig.canvas.get_renderer()
        strips = [ax for ax in fig.axes if ax.patches and ax.get_aspect() == 1.0 and ax.axison]
        assert strips, key
        for ax in strips:
            ab = ax.get_window_extent(r)
            labels = [t for c in ax.child_axes for t in c.get_xticklabels() if t.get_text()]
            assert labels, key  # every strip names its teeth
            for t in labels:
                tb = t.get_window_extent(r)
                assert tb.y0 >= ab.y1 - 0.5, (key, t.get_text())
        schem = [ax for ax in fig.axes if not ax.axison]
        assert len(schem) == 1, key
        ax = schem[0]
        names = [t for t in ax.texts if "axis" in t.get_text()]
        assert len(names) == 2, key
        for t in names:
            tb = t.get_window_extent(r)
            for line in ax.get_lines():
                hit = _inside(_display_points(line), tb, 0.0)
                assert not hit.any(), (key, t.get_text(), line.get_label())


def test_assembly_strips_are_tall_enough(pictures):
    """True-scale strips of at least an inch: D3's three 66 mm strips were half an inch of hatching."""
    _, figs = pictures
    for key, fig in _all(figs, "assembly"):
        r = fig.canvas.get_renderer()
        for ax in fig.axes:
            if ax.patches and ax.axison and ax.get_aspect() == 1.0:
                h_in = ax.get_window_extent(r).height / fig.dpi
                assert h_in >= 1.0, (key, h_in)
                x0, x1 = ax.get_xlim()
                y0, y1 = ax.get_ylim()
                w_in = ax.get_window_extent(r).width / fig.dpi
                assert (y1 - y0) / (x1 - x0) == pytest.approx(h_in / w_in, rel=0.02)  # true shape


def test_velocities_say_what_each_curve_is_and_hide_none(pictures):
    _, figs = pictures
    (fig,) = figs[("d3_external", "velocities")]
    symbols = set()
    for ax in fig.axes:
        lines = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
        for ln in lines:
            lab = ln.get_label()
            sym, _, words = lab.partition(":")
            assert len(words.split()) >= 3, lab  # a description, not a bare symbol
            symbols.add(sym.split("=")[0].strip())
        lo, hi = ax.get_ylim()
        for i, a in enumerate(lines):
            for b in lines[i + 1 :]:
                if np.max(np.abs(np.asarray(a.get_ydata()) - np.asarray(b.get_ydata()))) < 0.01 * (hi - lo):
                    # coinciding curves: the later one dashed and thinner so the first shows around it
                    assert b.get_linestyle() != a.get_linestyle() and b.get_linewidth() < a.get_linewidth(), (
                        a.get_label(),
                        b.get_label(),
                    )
    for s in ("V_w", "V_v", "V_vK", "V_dw", "V_dv", "V_sl", "V_d", "dtheta/dt"):
        assert s in symbols, s
