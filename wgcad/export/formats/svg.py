"""SVG drawing of a part's DXF layers (top view, mm, 1:1) with its gear-data table; plain text, no plotting library."""

from __future__ import annotations

import os
from xml.sax.saxutils import escape

import numpy as np

from wgcad.atomic import atomic_write
from wgcad.export.formats.arcs import bulge_centres

__all__ = ["svg_text", "write_svg"]

#: ACI colours used by wgcad's layers, as SVG colours (7 = black on paper).
ACI = {1: "#c00000", 2: "#b08000", 3: "#008000", 5: "#0040c0", 7: "#000000", 8: "#808080"}


def _f(v: float) -> str:
    t = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if t == "-0" else t


def _poly(pts, flip) -> str:
    return "M " + " L ".join(f"{_f(x)} {_f(flip(y))}" for x, y in pts) + " Z"


def _path(v, b, flip) -> str:
    e = np.roll(v, -1, axis=0)
    _, radius, theta = bulge_centres(v, e, b)
    out = [f"M {_f(v[0, 0])} {_f(flip(v[0, 1]))}"]
    for i in range(len(v)):
        if b[i] == 0:
            out.append(f"L {_f(e[i, 0])} {_f(flip(e[i, 1]))}")
        else:
            # y is flipped (SVG y runs down): a counter-clockwise arc becomes sweep-flag 0
            sweep = 0 if theta[i] > 0 else 1
            out.append(f"A {_f(radius[i])} {_f(radius[i])} 0 0 {sweep} {_f(e[i, 0])} {_f(flip(e[i, 1]))}")
    return " ".join(out) + " Z"


def svg_text(layers, title: str) -> str:
    """An SVG drawing of the layers (outlines, arc paths, circles, texts) in mm, y up as in the DXF."""
    pts = []
    for layer in layers:
        pts += [o for o in layer.outlines] + [v for v, _ in layer.paths]
        pts += [np.array([[cx - r, cy - r], [cx + r, cy + r]]) for cx, cy, r in layer.circles]
        pts += [np.array([[x, y - h], [x + 0.6 * h * len(t), y + h]]) for x, y, h, t in layer.texts]
    allp = np.vstack(pts) if pts else np.zeros((1, 2))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.03 * float(np.max(hi - lo)) + 1.0
    lo, hi = lo - pad, hi + pad
    w, h = hi - lo
    # SVG's y runs down: y is negated, so the drawing is not upside down and the gear's centre stays at (0, 0) in
    # the file's own coordinates (a reflection about the box's middle put it at (0, 3.3) mm on D1's drawing)
    flip = lambda y: -y  # noqa: E731
    stroke = max(0.02, 0.0008 * float(max(w, h)))
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_f(w)}mm" height="{_f(h)}mm" '
        f'viewBox="{_f(lo[0])} {_f(-hi[1])} {_f(w)} {_f(h)}">',
        f"<title>{escape(title)}</title>",
        f'<rect x="{_f(lo[0])}" y="{_f(-hi[1])}" width="{_f(w)}" height="{_f(h)}" fill="white"/>',
    ]
    for layer in layers:
        col = ACI.get(layer.color, "#000000")
        dash = (
            f' stroke-dasharray="{_f(8 * stroke)} {_f(3 * stroke)} {_f(stroke)} {_f(3 * stroke)}"'
            if layer.construction
            else ""
        )
        out.append(f'<g id="{escape(layer.name)}" fill="none" stroke="{col}" stroke-width="{_f(stroke)}"{dash}>')
        out += [f'<path d="{_poly(o, flip)}"/>' for o in layer.outlines]
        out += [f'<path d="{_path(v, b, flip)}"/>' for v, b in layer.paths]
        out += [f'<circle cx="{_f(cx)}" cy="{_f(flip(cy))}" r="{_f(r)}"/>' for cx, cy, r in layer.circles]
        out += [
            f'<text x="{_f(x)}" y="{_f(flip(y))}" font-size="{_f(hh)}" font-family="monospace" fill="{col}" '
            f'stroke="none">{escape(t)}</text>'
            for x, y, hh, t in layer.texts
        ]
        out.append("</g>")
    out.append("</svg>\n")
    return "\n".join(out)


def write_svg(path: str | os.PathLike, layers, title: str) -> None:
    """Write the SVG drawing, atomically."""
    atomic_write(path, svg_text(layers, title).encode("utf-8"))
