"""Pictures that show their subject (issue 43): the close-up framed on the tightest spot and marked, the exact minimum
drawn where the audit reports it, every drawn line in a legend, the pages' first view on the band that matters."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from conftest import TEMPLATES

import wgcad.export.pictures.drive as F
from wgcad import api
from wgcad.export.pictures.audit import audit_plot_data

#: an internal drive (tip contact) and the external one (the rigid teeth below the flexspline's)
CASES = ["d1_involute", "d3_external"]


@pytest.fixture(scope="module")
def audits():
    out = {}
    for name in CASES:
        run = api.audit(TEMPLATES / f"{name}.toml")
        out[name] = (run, audit_plot_data(run.drive, run.result))
    return out


def _legend_labels(ax) -> list[str]:
    leg = ax.get_legend()
    return [] if leg is None else [t.get_text() for t in leg.get_texts()]


@pytest.mark.parametrize("name", CASES)
def test_closeup_holds_the_tightest_spot(audits, name):
    """The close-up's limits hold both ends of the tightest gap, a tenth of the view clear of every edge; the ends
    lie on the drawn outlines of the worst tooth and a rigid tooth, as far apart as the audit reports (the outlines
    within the chord tolerance, 1 um, of the curves); the spot is marked with its figure in the legend."""
    import matplotlib.pyplot as plt

    run, data = audits[name]
    teeth, labels, rigid, overlap, title, spot = data["tightest"]
    reported = run.doc["worst"]["clearance_um"]
    assert abs(spot["um"] - reported) < 1e-3
    worst = shapely.Polygon(teeth[len(teeth) // 2])
    flex_end, rigid_end = shapely.Point(spot["flex"]), shapely.Point(spot["rigid"])
    assert 1e3 * worst.exterior.distance(flex_end) < 1.0
    assert min(1e3 * shapely.Polygon(r).exterior.distance(rigid_end) for r in rigid) < 1.0
    # the spot is the tightest place the picture shows: no rigid outline comes nearer the worst tooth by more than
    # the outlines' own error
    outline_gap = min(1e3 * worst.distance(shapely.Polygon(r)) for r in rigid)
    assert 1e3 * flex_end.distance(rigid_end) == pytest.approx(reported, abs=1e-3)
    assert outline_gap > reported - 2.0
    fig = F.tightest_spot_figure(teeth, labels, rigid, overlap, title, spot)
    try:
        centre = teeth[len(teeth) // 2].mean(axis=0)
        a_ref, r_ref = float(np.arctan2(centre[1], centre[0])), float(np.hypot(*centre))
        ends = F._unroll(np.stack([spot["flex"], spot["rigid"]]), r_ref, a_ref)
        close = fig.axes[1]
        (x0, x1), (y0, y1) = close.get_xlim(), close.get_ylim()
        mx, my = 0.1 * (x1 - x0), 0.1 * (y1 - y0)
        for x, y in ends:
            assert x0 + mx < x < x1 - mx and y0 + my < y < y1 - my, (name, (x, y), (x0, x1), (y0, y1))
        # the gap itself reads at the close-up's scale: at least 3 % of its width
        assert np.hypot(*(ends[0] - ends[1])) > 0.03 * (x1 - x0)
        assert any(f"{reported:.2f} um" in t for t in _legend_labels(close)), _legend_labels(close)
    finally:
        plt.close(fig)


def test_closeup_limits_without_a_spot_keep_the_old_framing():
    tooth = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert F.closeup_limits(None, None, tooth) == ((0.5 - 0.8, 0.5 + 0.8), (0.5 - 0.8, 0.5 + 0.8))
    ends = np.array([[0.0, 0.0], [0.3, 0.0]])
    (x0, x1), _ = F.closeup_limits(ends, None, tooth)
    assert x0 < 0.0 - 0.1 * (x1 - x0) and x1 > 0.3 + 0.1 * (x1 - x0)


@pytest.mark.parametrize("name", CASES)
def test_vs_angle_reaches_the_reported_minimum(audits, name):
    """The figure against generator angle reads the exact curves near the minimum: its smallest value is the audit's
    (the polygons read 0.29 um below it on D1), and the audit's minimum is drawn, in the legend, with every curve."""
    import matplotlib.pyplot as plt

    run, data = audits[name]
    kind, args = data["vs_angle"]
    assert kind == "curve"
    reported = run.doc["min_clearance_um"]
    assert abs(min(np.nanmin(args[1]), np.nanmin(args[2])) - reported) < 0.01
    fig = F.clearance_vs_angle_figure(*args)
    try:
        for ax in fig.axes:
            drawn = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
            # every curve is named (an unnamed line is only the zero line, which the panel's title explains)
            assert all(len(ln.get_xdata()) == 2 for ln in ax.get_lines() if ln not in drawn)
            labels = _legend_labels(ax)
            assert all(ln.get_label() in labels for ln in drawn), labels
            lo, hi = ax.get_ylim()
            if any("the audit's minimum" in t for t in labels):
                assert lo < reported < hi
        assert any(f"{reported:.3f}" in t for ax in fig.axes for t in _legend_labels(ax))
    finally:
        plt.close(fig)


def _inside_with_margin(value: float, rng, margin: float = 0.05) -> bool:
    lo, hi = rng
    return lo + margin * (hi - lo) <= value <= hi - margin * (hi - lo)


def test_audit_page_opens_on_the_band_that_matters(audits):
    """The page's passage plot opens on the PNG's band (at most 250 um on D1, not the 2000 um out of mesh) holding the
    minimum and the entry gap 5 % of the view clear of its edges; the plot against generator angle opens on the
    ripple around the audit's minimum (not 0 to 8.5 um); the full range is a button away; one word, "flank"."""
    from wgcad.export.pages.audit import audit_figures, audit_html

    run, data = audits["d1_involute"]
    figs = audit_figures(run.drive, run.doc, data)
    prof = figs["profile"].to_dict()["layout"]
    rng = prof["yaxis"]["range"]
    assert rng[1] <= 250.0
    for value in (run.doc["min_clearance_um"], run.doc["entry_gap_um"]):
        assert _inside_with_margin(value, rng), (value, rng)
    curves = [t for t in figs["profile"].data if t.mode == "lines"]
    assert max(np.nanmax(t.y) for t in curves) > 4 * rng[1]  # the band is a view, the data all there
    vs = figs["vs_angle"].to_dict()["layout"]
    vr = vs["yaxis"]["range"]
    kind, args = data["vs_angle"]
    ys = np.concatenate([args[1], args[2]])
    assert _inside_with_margin(run.doc["min_clearance_um"], vr), vr
    assert vr[0] < np.nanmin(ys) and np.nanmax(ys) < vr[1]
    assert vr[1] - vr[0] < 2.0 * np.ptp(ys) + 0.011  # the ripple fills the view
    for layout in (prof, vs):
        buttons = layout["updatemenus"][0]["buttons"]
        assert any(b["args"][0].get("yaxis.autorange") is True for b in buttons)
    names = [t.name for f in figs.values() for t in f.data if t.name]
    assert not [n for n in names if "edge" in n], names
    page = audit_html(run.drive, run.result, run.doc, data)
    assert " - um" not in page and "tooth angle - deg" not in page
    if run.doc["entry"]["pinch_um"] is None:
        assert "<th>entry pinch</th><td>none</td>" in page


# ---------------------------------------------------------------- sweep


@pytest.fixture(scope="module")
def d2_sweep(tmp_path_factory):
    """The bundled D2 tolerance sweep cut to 40 samples (its seed): one of them fails the 120 arcsec limit."""
    import tomllib

    from wgcad.sweep.runner import run_sweep
    from wgcad.sweep.spec import parse_spec
    from wgcad.sweep.store import Store
    from wgcad.sweep.summary import summarize
    from wgcad.sweep.tasks import columns_of

    data = tomllib.loads((TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml").read_text())
    data["sweep"]["samples"] = 40
    data["sweep"]["design"] = str(TEMPLATES / "d2_imperfect.toml")
    spec = parse_spec(data)
    out = tmp_path_factory.mktemp("d2_sweep")
    info = run_sweep(spec, out, workers=0, batch=1)
    pl = spec.payload()
    cols = Store(out, pl["fingerprint"], columns_of(pl), spec.total).read()
    return spec, cols, summarize(spec, cols), info


def _sweep_figures(monkeypatch, fn, *args):
    import wgcad.export.pictures.sweep as SF

    monkeypatch.setattr(SF, "_png", lambda fig, plt: fig)
    return getattr(SF, fn)(*args)


def test_sweep_does_not_rank_parameters_from_one_failure(d2_sweep, monkeypatch):
    """One failing sample in 40 decides no ranking: the summary and the picture say so, with the count and the least
    needed, and rank by the figure's own correlation instead; a batch of one reads "1 sample per task"."""
    import matplotlib.pyplot as plt

    from wgcad.sweep.summary import MIN_FAILING_TO_RANK, failing_samples, format_summary

    spec, cols, summ, info = d2_sweep
    n_fail = failing_samples(summ)
    assert 0 < n_fail < MIN_FAILING_TO_RANK  # the case the issue saw: 1 of 40
    text = format_summary(summ, info)
    assert "(rank correlation with failing)" not in text
    assert f"not ranked, {n_fail} failing sample{'' if n_fail == 1 else 's'} of 40" in text, text
    assert "1 sample per task" in text and "1 samples" not in text
    fig = _sweep_figures(monkeypatch, "sensitivity_png", spec, cols, summ)
    try:
        title = fig.axes[0].get_title()
        assert "failures not ranked" in title and f"{n_fail} failing sample" in title, title
        # ranked by the correlation with the figure: the bars' lengths fall from the top
        bars = sorted(fig.axes[0].patches, key=lambda b: -b.get_y())
        widths = [abs(b.get_width()) for b in bars]
        assert widths == sorted(widths, reverse=True)
    finally:
        plt.close(fig)


def test_a_constant_figure_is_said_constant(d2_sweep, monkeypatch):
    """ke_deep_overlap_fraction is 0 in every sample: its panel says "constant", it draws no histogram bar of a made-up
    width (it was a bar over 0..0.1)."""
    import matplotlib.pyplot as plt

    spec, cols, summ, _ = d2_sweep
    ok = cols["status"] == "ok"
    assert np.ptp(cols["ke_deep_overlap_fraction"][ok]) == 0.0
    fig = _sweep_figures(monkeypatch, "histograms_png", spec, cols, summ)
    try:
        ax = next(a for a in fig.axes if a.get_title().startswith("ke_deep_overlap_fraction"))
        assert "(constant)" in ax.get_title()
        assert not ax.patches  # no bar
        assert any("constant: all 40 samples 0" in t.get_text() for t in ax.texts)
    finally:
        plt.close(fig)


def test_a_limit_contour_is_in_the_legend():
    import matplotlib.pyplot as plt

    import wgcad.export.pictures.sweep as SF

    fig, ax = plt.subplots()
    try:
        m = np.array([[-5.0, -2.0], [1.0, 9.0], [3.0, 4.0]])
        ax.imshow(m.T, origin="lower")
        SF._limit_contours(ax, m, (0.0, None))
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["limit min 0 (interpolated)"]
    finally:
        plt.close(fig)


# ---------------------------------------------------------------- design


def test_design_best_has_its_own_name_and_the_search_title_fits(tmp_path, monkeypatch):
    """The best design's file names itself (its audits were labelled with the base's "D1 involute (S1)"), and the
    search picture's title lies inside the picture (it ran off at "...(11 sto")."""
    import matplotlib.pyplot as plt

    import wgcad.export.files.synthesis as SYN
    from wgcad.cli import main
    from wgcad.design import load_design

    base = TEMPLATES / "d1_involute.toml"
    req = tmp_path / "req.toml"
    req.write_text(
        f'[requirements]\nname = "D1 with its flexspline tooth count free, ratio 100 exactly, clearance first"\n'
        f'base = "{base}"\nratio = 100.0\nobjective = "min_clearance"\ntrials = 12\n[free]\n"drive.z_flex" = [196, 204]\n'
    )
    figs = []
    orig = SYN.search_plot
    monkeypatch.setattr(SYN, "search_plot", lambda res: figs.append(orig(res)) or figs[-1])
    monkeypatch.setattr(plt, "close", lambda *a, **k: None)
    out = tmp_path / "out"
    assert main(["design", str(req), "--out", str(out), "--no-explain", "--quiet"]) == 0
    base_name = load_design(base).drive.name
    best = load_design(out / "req_best.toml").drive.name
    assert best != base_name and best.startswith(base_name) and "design best, trial" in best, best
    (fig,) = figs
    try:
        fig.canvas.draw()
        box, title = fig.bbox, fig.axes[0].title.get_window_extent()
        assert box.x0 <= title.x0 and title.x1 <= box.x1 and title.y1 <= box.y1, (title, box)
        assert "stopped" in fig.axes[0].get_title()
    finally:
        fig.clf()


# ---------------------------------------------------------------- kinematic error


@pytest.fixture(scope="module")
def d2_ke():
    return api.kinematic_error(TEMPLATES / "d2_imperfect.toml")


def test_ke_spectrum_marks_the_strongest_orders(d2_ke, monkeypatch):
    """The summary's four strongest orders (D2: 100, 301, 300, 101) are marked in the PNG's spectrum, inside its
    axis, and named in its legend with every other drawn line; the page marks them too and keeps its legends
    under the plots (beside them they took 40 % of the width)."""
    import matplotlib.pyplot as plt

    import wgcad.export.pictures.ke as KF
    from wgcad.export.pages.ke import _ke, _spectrum

    run = d2_ke
    top = [(t["order"], t["amplitude_arcsec"]) for t in run.doc["spectrum_top"][:4]]
    assert {300.0, 301.0} & {o for o, _ in top}
    fig = KF.ke_figure("D2", run.res, run.orders, run.amp, run.expected, run.intr, top)
    try:
        spec = fig.axes[2]
        marks = next(ln for ln in spec.get_lines() if ln.get_label().startswith("strongest"))
        assert sorted(marks.get_xdata()) == sorted(o for o, _ in top)
        x0, x1 = spec.get_xlim()
        y0, y1 = spec.get_ylim()
        assert all(x0 < o < x1 for o, _ in top) and all(y0 < y < y1 for y in marks.get_ydata())
        labels = [t.get_text() for t in spec.get_legend().get_texts()]
        assert all(f"{o:g} (" in labels[-1] for o, _ in top), labels
        named = {ln.get_label() for ln in spec.get_lines() if not ln.get_label().startswith("_")}
        assert named <= set(labels)
    finally:
        plt.close(fig)
    import plotly.graph_objects as go

    page = _spectrum(go, run)
    strongest = [t for t in page.data if t.name and t.name.startswith("strongest")]
    assert len(strongest) == 1 and sorted(strongest[0].x) == sorted(o for o, _ in top)
    for f in (page, _ke(go, run)):
        assert f.layout.legend.orientation == "h" and f.layout.legend.y < 0


# ---------------------------------------------------------------- rating


def test_rating_legends_are_readable_and_inside_the_picture():
    """Every legend of the datasheet picture at 8 pt or more (they were 6 and 7 pt) and inside the figure."""
    import matplotlib.pyplot as plt

    from wgcad.export.pictures.drive import MIN_FONT_PT
    from wgcad.export.pictures.rating import rating_figure

    ds = api.rating(TEMPLATES / "d1_involute.toml").datasheet
    fig = rating_figure(ds)
    try:
        fig.canvas.draw()
        legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
        assert len(legends) >= 6
        box = fig.bbox
        for leg in legends:
            assert min(t.get_fontsize() for t in leg.get_texts()) >= MIN_FONT_PT
            b = leg.get_window_extent()
            assert box.x0 <= b.x0 and b.x1 <= box.x1 and box.y0 <= b.y0 and b.y1 <= box.y1, (b, box)
    finally:
        plt.close(fig)
