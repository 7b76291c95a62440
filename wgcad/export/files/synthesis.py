"""The files of a design search (``wgcad design``), written in one atomic batch: the chosen design(s) as commented
design files, every candidate as CSV, the Pareto front as CSV, the search's JSON and its picture."""

from __future__ import annotations

import csv
import io
import textwrap
from pathlib import Path

from ...atomic import atomic_batch
from ...report.synthesis import design_text, search_json, trial_rows
from ...synthesis.requirements import OBJECTIVES
from ..formats.json_text import json_text
from ..pictures.mpl import png_bytes, pyplot

__all__ = ["write_search_files", "search_figure", "search_plot"]


def _label(o: str) -> str:
    """An objective's axis label with its unit: the meaning's words before any parenthesis."""
    return OBJECTIVES[o][1].split(" (")[0]


def _csv(header, rows) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def search_figure(res) -> bytes:
    """The search's picture as PNG bytes (:func:`search_plot`)."""
    return png_bytes(search_plot(res), tight_layout=True, dpi=110)


def search_plot(res):
    """One objective: its value for every candidate in trial order (feasible ones filled, the best marked). Two: the
    objectives against each other, the Pareto front joined. The title names the search on its own line(s), the
    counts on the next: it fits the picture's width."""
    plt = pyplot()
    req = res.req
    objs = req.objectives
    fig, ax = plt.subplots(figsize=(8, 5))
    feas = [(i, ev) for i, ev in enumerate(res.evaluations) if ev.feasible]
    if len(objs) == 1:
        o = objs[0]
        xs = [i for i, ev in feas if o in ev.objectives]
        ys = [ev.objectives[o] for i, ev in feas if o in ev.objectives]
        ax.plot(xs, ys, "o", color="tab:blue", label="feasible")
        other = [
            (i, ev.objectives[o]) for i, ev in enumerate(res.evaluations) if not ev.feasible and o in ev.objectives
        ]
        if other:
            ax.plot(*zip(*other), "x", color="0.6", label="infeasible (where the objective was computed)")
        if res.best is not None:
            ax.plot(
                [res.evaluations.index(res.best)], [res.best.objectives[o]], "*", ms=16, color="tab:red", label="best"
            )
        ax.set_xlabel("candidate (trial order)")
        ax.set_ylabel(_label(o))
    else:
        a, b = objs
        pts = [(ev.objectives[a], ev.objectives[b]) for _, ev in feas if a in ev.objectives and b in ev.objectives]
        if pts:
            ax.plot(*zip(*pts), "o", color="tab:blue", label="feasible")
        front = sorted(
            (ev.objectives[a], ev.objectives[b]) for ev in res.pareto if a in ev.objectives and b in ev.objectives
        )
        if front:
            ax.plot(*zip(*front), "-*", ms=12, color="tab:red", label="Pareto front")
        ax.set_xlabel(_label(a))
        ax.set_ylabel(_label(b))
    n_infeasible = len(res.evaluations) - len(feas)
    name = "\n".join(textwrap.wrap(req.name, 70)) or "design search"
    counts = (
        f"{len(feas)} feasible of {len(res.evaluations)} candidates ({n_infeasible} stopped at a check they failed)"
    )
    ax.set_title(f"{name}\n{counts}", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def write_search_files(res, out_dir, stem: str, base_text: str, plot: bool = True) -> list[Path]:
    """Write the search's files into ``out_dir`` (atomically, together); returns their paths."""
    out_dir = Path(out_dir)
    files = {}
    if res.best is not None:
        files[out_dir / f"{stem}_best.toml"] = design_text(base_text, res, res.best).encode()
    if len(res.req.objectives) > 1:
        for k, ev in enumerate(res.pareto):
            files[out_dir / f"{stem}_pareto_{k + 1}.toml"] = design_text(
                base_text, res, ev, f"Pareto #{k + 1}"
            ).encode()
        header, rows = trial_rows(res)
        idx = {id(ev) for ev in res.pareto}
        files[out_dir / f"{stem}_pareto.csv"] = _csv(
            header, [r for r, ev in zip(rows, res.evaluations) if id(ev) in idx]
        ).encode()
    files[out_dir / f"{stem}_trials.csv"] = _csv(*trial_rows(res)).encode()
    files[out_dir / f"{stem}_search.json"] = (json_text(search_json(res)) + "\n").encode()
    if plot:
        files[out_dir / f"{stem}_search.png"] = search_figure(res)
    with atomic_batch() as batch:
        for path, data in files.items():
            Path(batch.temp_path(path)).write_bytes(data)
    return list(files)
