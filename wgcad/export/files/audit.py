"""The files of an audit as a library call: its JSON document, its regression baseline, the three PNG pictures
and the interactive page, written in one atomic batch. ``wgcad audit`` wraps it: flags, standard output, the
bar, printing."""

from __future__ import annotations

from pathlib import Path

from ...atomic import atomic_batch
from ..formats.json_text import json_text
from ..pages.audit import audit_html
from ..pictures.audit import audit_plot_data, audit_pngs

__all__ = ["plot_paths", "write_audit_files"]


def plot_paths(plot) -> list[tuple[str, Path]]:
    """The three pictures of ``--plot PATH``: ``PATH_profile.png``, ``PATH_vs_angle.png``, ``PATH_tightest.png``."""
    p = Path(plot)
    return [(suffix, p.with_name(f"{p.stem}_{suffix}.png")) for suffix in ("profile", "vs_angle", "tightest")]


def write_audit_files(
    run, *, json_path=None, baseline=None, baseline_path=None, plot=None, html=None, on_pictures=None
) -> list[Path]:
    """Write what is asked of the audit ``run`` (:func:`wgcad.services.audit_report.audit_document`): the JSON document
    to ``json_path``, the baseline document ``baseline`` to ``baseline_path``, the pictures named after ``plot``
    (:func:`plot_paths`), the page to ``html``. Nothing is written unless all is; ``on_pictures()`` is called
    when the pictures start. Returns the paths written."""
    texts = []
    if json_path:
        texts.append((Path(json_path), json_text(run.doc) + "\n"))
    if baseline_path:
        texts.append((Path(baseline_path), json_text(baseline) + "\n"))
    if not (texts or plot or html):
        return []
    files = []
    with atomic_batch() as batch:
        for path, text in texts:
            Path(batch.temp_path(path)).write_text(text)
            files.append(path)
        if plot or html:
            if on_pictures is not None:
                on_pictures()

            data = audit_plot_data(run.drive, run.result)
        if plot:
            pngs = dict(audit_pngs(run.drive, run.result, data))
            for suffix, path in plot_paths(plot):
                Path(batch.temp_path(path)).write_bytes(pngs[suffix])
                files.append(path)
        if html:
            Path(batch.temp_path(html)).write_text(audit_html(run.drive, run.result, run.doc, data), encoding="utf-8")
            files.append(Path(html))
    return files
