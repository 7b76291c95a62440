"""The kinematic-error and load pictures as a designer reads them (issue 23, item 6): labels that do not print over
each other, an axis that shows the drive and not a clamp, legends that name curves in words and sit beside what
they explain, ticks where the values lie. Each figure is caught before it is rendered to PNG and inspected."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import TEMPLATES

from wgcad.cli import main


@pytest.fixture
def caught(monkeypatch):
    """Every figure the KE and load picture modules render, kept open: ``list`` of matplotlib figures."""
    import wgcad.export.pictures.ke as kf
    import wgcad.export.pictures.load as lf

    figs = []

    def keep(fig, *a, **k):
        fig.canvas.draw()
        figs.append(fig)
        return b"\x89PNG\r\n\x1a\n"

    monkeypatch.setattr(kf, "png_bytes", keep)
    monkeypatch.setattr(lf, "png_bytes", keep)
    return figs


def _lines_with_data(ax):
    return [ln for ln in ax.get_lines() if np.isfinite(np.asarray(ln.get_ydata(), float)).any()]


def test_ke_spectrum_names_the_orders_in_its_legend_over_four_decades(caught, tmp_path):
    """D2: the rigid gear's order 100 and the flexspline's 101 were two texts at their lines, printed over each
    other, and the log axis ran over 8 decades to a clamp at 1e-6. Now no text in the spectrum, the orders in its
    legend by gear, and the axis spans four decades below the strongest order."""
    assert main(["ke", str(TEMPLATES / "d2_imperfect.toml"), "--per-mesh", "4", "--plot", str(tmp_path / "k")]) == 0
    ke = caught[0]
    spec = ke.axes[2]
    assert not spec.texts
    labels = [t.get_text() for t in spec.get_legend().get_texts()]
    assert any(lab.startswith("rigid orders: 100") for lab in labels)
    assert any(lab.startswith("flexspline orders: 101") for lab in labels)
    lo, hi = spec.get_ylim()
    amp = next(ln for ln in spec.get_lines() if ln.get_label() == "amplitude")
    a_max = float(np.max(amp.get_ydata()))
    # four decades below the strongest order; above it room for the strongest orders' markers (drawn at 2x)
    assert lo == pytest.approx(1e-4 * a_max, rel=1e-12)
    assert 2.0 * a_max < hi <= 5.0 * a_max
    # the flank picture: every engagement named in words (not 'single_left'), every listed curve drawn in view
    flank = caught[-1]
    names = [t.get_text() for t in flank.legends[0].get_texts()]
    assert names and not any("_" in n for n in names)
    for ax in flank.axes:
        for ln in _lines_with_data(ax):
            y = np.asarray(ln.get_ydata(), float)
            y0, y1 = ax.get_ylim()
            assert np.nanmin(y) >= y0 - 1e-9 and np.nanmax(y) <= y1 + 1e-9


def test_load_pictures_legend_beside_the_spikes_and_ticks_where_the_values_are(caught, tmp_path):
    """D1 under load: the forces picture's legend covered the force spike it is about; the compare plot (involute
    gaps of a few um against cycloidal ones near 180 um on a symlog axis) had no tick in the band where the
    involute's values lie."""
    design = TEMPLATES / "d1_involute.toml"
    args = ["audit", str(design), "--torque-nm", "0,1000", "--plot", str(tmp_path / "l"), "--quiet"]
    assert main([*args, "--compare", str(TEMPLATES / "d1_cycloidal.toml")]) in (0, 1)
    forces = next(f for f in caught if f.axes[0].get_ylabel().startswith("tooth force"))
    ax = forces.axes[0]
    leg = ax.get_legend().get_window_extent()
    axes_box = ax.get_window_extent()
    assert leg.x0 >= axes_box.x1 - 1  # beside the panel
    compare = caught[-1]
    cax = compare.axes[0]
    assert cax.get_yscale() == "symlog"
    ticks = [t for t in cax.get_yticks() if cax.get_ylim()[0] <= t <= cax.get_ylim()[1]]
    assert any(0 < abs(t) <= 10 for t in ticks), ticks
