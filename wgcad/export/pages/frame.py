"""The frame every interactive page shares: one self-contained HTML file, plotly.js inlined once, figures and tables.

Nothing is fetched when a page is viewed: it opens from a disk, a mail or an
archive. plotly is imported only here and in the page builders, when a page is
asked for (``--html``).
"""

from __future__ import annotations

import html

import numpy as np

__all__ = ["CSS", "GLOSSARY", "fmt", "figure", "table", "notes", "page"]

#: where the names on every page are defined (the page links it in its footer; a path of the source tree)
GLOSSARY = "docs/glossary.md"

CSS = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 1200px; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.5em 0; } td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
th { background: #f3f3f3; } .bad { color: #b00; font-weight: bold; } .ok { color: #070; font-weight: bold; }
.note { color: #555; font-size: 0.92em; } .fig { margin: 0.5em 0 1.5em 0; }
"""


def fmt(v, nd: int = 3) -> str:
    """A figure for a table cell: ``-`` for None or a non-finite number, escaped text otherwise."""
    if v is None:
        return "-"
    if isinstance(v, float):
        return "-" if not np.isfinite(v) else f"{v:.{nd}f}"
    return html.escape(str(v))


def figure(fig, div_id: str) -> str:
    """A plotly figure as a ``<div>`` (the page carries the script)."""
    html_div = fig.to_html(full_html=False, include_plotlyjs=False, div_id=div_id, config={"displaylogo": False})
    return '<div class="fig">' + html_div + "</div>"


def table(rows, head=None) -> str:
    """Rows of cells (already formatted text; the first cell of each row a header) as a ``<table>``."""
    out = []
    if head:
        out.append("<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in head) + "</tr>")
    for r in rows:
        out.append(f"<tr><th>{r[0]}</th>" + "".join(f"<td>{c}</td>" for c in r[1:]) + "</tr>")
    return "<table>" + "".join(out) + "</table>"


def notes(items, title: str = "NOT CHECKED:") -> str:
    """A list of notes (what a run did not check), or nothing."""
    items = list(items)
    if not items:
        return ""
    li = "".join(f"<li>{html.escape(str(n))}</li>" for n in items)
    return f"<p class='note'>{html.escape(title)}</p><ul class='note'>{li}</ul>"


def page(title: str, command: str, head: list[str], figs: list[tuple[str, str]], tail: str = "") -> str:
    """The whole page: ``head`` (HTML blocks: verdict, tables, notes) then each ``(title, figure div)``."""
    from plotly.offline import get_plotlyjs

    body = [f"<h1>{html.escape(title)}</h1>", *head]
    for t, div in figs:
        body += [f"<h2>{html.escape(t)}</h2>", div]
    return (
        "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}: wgcad {html.escape(command)}</title><style>{CSS}</style>"
        f"<script type='text/javascript'>{get_plotlyjs()}</script></head><body>\n"
        + "\n".join(body)
        + (
            tail
            or "\n<p class='note'>wgcad: every figure here is also in the JSON; the page loads nothing from the network.</p>"
        )
        + f"\n<footer class='note'>Terms (backlash, lost motion, wind-up offset, rated and design torque, ...): "
        f"<a href='{GLOSSARY}'>{GLOSSARY}</a>, wgcad's glossary.</footer>" + "\n</body></html>\n"
    )
