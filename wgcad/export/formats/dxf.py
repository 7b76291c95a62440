"""DXF export and read-back of 2D outlines: one closed LWPOLYLINE per outline (straight or with arc bulges), circles as CIRCLE, text lines as TEXT, in mm."""

from __future__ import annotations

import contextlib
import io
import math
import os
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from wgcad.atomic import atomic_write
from wgcad.constants import DUPLICATE_TOL  # noqa: F401  (re-exported for callers)
from wgcad.errors import InputFileError
from wgcad.export.formats.arcs import arc_points
from wgcad.export.formats.rings import clean_outline, min_spacing

__all__ = [
    "DxfLayer",
    "build_dxf",
    "write_dxf",
    "dxf_text",
    "prepare",
    "read_dxf",
    "audit_dxf",
    "clean_outline",
    "clean_path",
]

#: DXF version written: R2010 (AC1024), read by every current CAD program.
DXF_VERSION = "R2010"

#: ``$INSUNITS`` code for millimetres.
INSUNITS_MM = 4

#: ``$MEASUREMENT`` 1 = metric.
MEASUREMENT_METRIC = 1

#: The CENTER linetype of construction layers: ISO-style long dash, gap, short dash, gap (mm; total length first).
CENTER_PATTERN = (20.0, 12.0, -3.0, 2.0, -3.0)
CENTER_DESCRIPTION = "Center ____ _ ____ _"


def is_valid_layer_name(name: str) -> bool:
    """A plain DXF layer name: 1-255 printable characters that ezdxf's table-name rule accepts, not an
    AutoCAD-special ``*`` layer (wgcad never writes one; ``|`` is allowed: external-reference layers)."""
    from ezdxf.lldxf.validator import is_valid_table_name

    return 0 < len(name) <= 255 and name.isprintable() and not name.startswith("*") and is_valid_table_name(name)


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64)  # own copy, so the caller's array stays writable
    a.setflags(write=False)
    return a


@dataclass(frozen=True, slots=True)
class DxfLayer:
    """One DXF layer: closed outlines and circles, in mm.

    Parameters
    ----------
    name : str
        Layer name (DXF rules: no ``<>/\\":;?*|=`` characters).
    outlines : tuple of (N, 2) float64 arrays
        Closed polygons (closing edge implicit), counter-clockwise by wgcad
        convention (not enforced: DXF does not care). Stored read-only.
    circles : tuple of (cx, cy, r) float tuples
        Circle centres and radii, ``r > 0``.
    color : int
        AutoCAD Color Index of the layer, 1..255 (7 = white/black).
    paths : tuple of ((N, 2) float, (N,) float) pairs
        Closed paths of arcs: vertices and the bulge ``tan(theta/4)`` of the
        segment starting at each vertex (an :class:`~wgcad.export.formats.arcs.ArcPath`
        also works). Written as LWPOLYLINE with bulges.
    texts : tuple of (x, y, height, str)
        Single-line texts (lower-left corner, character height, mm).
    construction : bool
        Construction geometry, not to be cut: the layer gets the CENTER
        linetype and is marked not to plot (a CAM program takes its cutting
        contours from the other layers).
    """

    name: str
    outlines: tuple = field(default=())
    circles: tuple = field(default=())
    color: int = 7
    paths: tuple = field(default=())
    texts: tuple = field(default=())
    construction: bool = False

    def __post_init__(self):
        if not isinstance(self.name, str) or not is_valid_layer_name(self.name):
            raise ValueError(f"DXF layer name {self.name!r} is not valid")
        if not (isinstance(self.color, (int, np.integer)) and 1 <= self.color <= 255):
            raise ValueError(f"layer {self.name}: color must be an ACI number 1..255, got {self.color!r}")
        outlines = []
        for k, o in enumerate(self.outlines):
            a = np.asarray(o, dtype=np.float64)
            if a.ndim != 2 or a.shape[1] != 2:
                raise ValueError(f"layer {self.name}: outline {k} must be (N, 2), got shape {a.shape}")
            outlines.append(_readonly(a))
        circles = []
        for k, c in enumerate(self.circles):
            cx, cy, r = (float(v) for v in c)
            if not (math.isfinite(cx) and math.isfinite(cy) and math.isfinite(r) and r > 0):
                raise ValueError(f"layer {self.name}: circle {k} must have finite centre and r > 0, got {c!r}")
            circles.append((cx, cy, r))
        paths = []
        for k, p in enumerate(self.paths):
            v, b = (p.vertices, p.bulges) if hasattr(p, "bulges") else p
            v, b = np.asarray(v, dtype=np.float64), np.asarray(b, dtype=np.float64)
            if v.ndim != 2 or v.shape[1] != 2 or b.shape != (len(v),):
                raise ValueError(f"layer {self.name}: path {k} must be (N, 2) vertices and (N,) bulges")
            if not (np.all(np.isfinite(v)) and np.all(np.abs(b) <= 1.0)):
                raise ValueError(
                    f"layer {self.name}: path {k} needs finite vertices and |bulge| <= 1 (at most half circles)"
                )
            paths.append((_readonly(v), _readonly(b)))
        texts = []
        for k, t in enumerate(self.texts):
            x, y, h, text = t
            if not (math.isfinite(x) and math.isfinite(y) and h > 0 and isinstance(text, str) and "\n" not in text):
                raise ValueError(f"layer {self.name}: text {k} must be (x, y, height > 0, one line)")
            texts.append((float(x), float(y), float(h), text))
        object.__setattr__(self, "paths", tuple(paths))
        object.__setattr__(self, "texts", tuple(texts))
        object.__setattr__(self, "outlines", tuple(outlines))
        object.__setattr__(self, "circles", tuple(circles))
        object.__setattr__(self, "color", int(self.color))


@dataclass(frozen=True, slots=True)
class Prepared:
    """A layer as it is written: outlines and paths cleaned (see :func:`prepare`)."""

    name: str
    color: int
    construction: bool
    outlines: tuple
    paths: tuple
    circles: tuple
    texts: tuple


def prepare(layers):
    """The layers cleaned for writing, and the drawing's bounding box.

    Each outline goes through :func:`clean_outline`, each path through
    :func:`clean_path`; the box covers outlines, the arcs of paths (not only
    their vertices) and circles (texts are not measured).

    Returns
    -------
    list of Prepared, (2,) lower corner, (2,) upper corner
        The corners are ``+inf``/``-inf`` when nothing was measured.

    Raises
    ------
    ValueError
        On a duplicate layer name (case-insensitive, as in DXF) or an outline
        with fewer than 3 distinct vertices.
    """
    lo = np.array([np.inf, np.inf])
    hi = -lo
    seen = set()
    out = []
    for layer in layers:
        if layer.name.lower() in seen:
            raise ValueError(f"DXF layer name {layer.name!r} is used twice")
        seen.add(layer.name.lower())
        outlines, paths = [], []
        for k, outline in enumerate(layer.outlines):
            try:
                pts = clean_outline(outline)
            except ValueError as exc:
                raise ValueError(f"layer {layer.name}: outline {k}: {exc}") from None
            outlines.append(pts)
            lo = np.minimum(lo, pts.min(axis=0))
            hi = np.maximum(hi, pts.max(axis=0))
        for k, (v, b) in enumerate(layer.paths):
            try:
                v, b = clean_path(v, b)
            except ValueError as exc:
                raise ValueError(f"layer {layer.name}: path {k}: {exc}") from None
            paths.append((v, b))
            # bounding box of the arcs, not only of their vertices
            pts = arc_points(v, np.roll(v, -1, axis=0), b, 9).reshape(-1, 2)
            lo = np.minimum(lo, pts.min(axis=0))
            hi = np.maximum(hi, pts.max(axis=0))
        for cx, cy, r in layer.circles:
            lo = np.minimum(lo, (cx - r, cy - r))
            hi = np.maximum(hi, (cx + r, cy + r))
        out.append(
            Prepared(
                layer.name, layer.color, layer.construction, tuple(outlines), tuple(paths), layer.circles, layer.texts
            )
        )
    return out, lo, hi


def build_dxf(layers):
    """Build an in-memory DXF R2010 drawing of the layers with ezdxf.

    Each outline becomes one closed LWPOLYLINE (after :func:`clean_outline`),
    each circle one CIRCLE; entities take their layer's colour (BYLAYER).
    The header says millimetres (``$INSUNITS`` 4, ``$MEASUREMENT`` 1) and
    ``$EXTMIN``/``$EXTMAX`` hold the drawing's bounding box so viewers can
    zoom to it. :func:`write_dxf` writes this drawing; it is the one to extend with ezdxf.

    Parameters
    ----------
    layers : iterable of DxfLayer
        Layer names must be unique (case-insensitive, as in DXF).

    Returns
    -------
    ezdxf.document.Drawing

    Raises
    ------
    ValueError
        On a duplicate layer name or an outline with fewer than 3 distinct
        vertices.
    """
    import ezdxf  # here, not at the top: the modules that only build layers (SVG, PNG) need no ezdxf

    prepared, lo, hi = prepare(layers)
    with _fixed_metadata():
        doc = ezdxf.new(DXF_VERSION)
    doc.header["$INSUNITS"] = INSUNITS_MM
    doc.header["$MEASUREMENT"] = MEASUREMENT_METRIC
    msp = doc.modelspace()
    for layer in prepared:
        if layer.name.lower() not in ("0", "defpoints"):
            doc.layers.add(layer.name, color=layer.color)
        else:
            doc.layers.get(layer.name).color = layer.color
        if layer.construction:
            if "CENTER" not in doc.linetypes:
                # ISO-style centre line: long dash, gap, short dash, gap (mm)
                doc.linetypes.add("CENTER", pattern=list(CENTER_PATTERN), description=CENTER_DESCRIPTION)
            lay = doc.layers.get(layer.name)
            lay.dxf.linetype = "CENTER"
            lay.dxf.plot = 0  # construction: not plotted, not a contour to cut
        attribs = {"layer": layer.name}
        for pts in layer.outlines:
            # add_lwpolyline(points) appends vertex by vertex with
            # np.concatenate: quadratic, seconds for 40k points. Set the
            # (n, 5) x, y, start width, end width, bulge array in one go.
            e = msp.add_lwpolyline([], close=True, dxfattribs=attribs)
            e.lwpoints.set(np.column_stack([pts, np.zeros((len(pts), 3))]))
        for v, b in layer.paths:
            e = msp.add_lwpolyline([], close=True, dxfattribs=attribs)
            e.lwpoints.set(np.column_stack([v, np.zeros((len(v), 2)), b]))
        for cx, cy, r in layer.circles:
            msp.add_circle((cx, cy), r, dxfattribs=attribs)
        for x, y, h, text in layer.texts:
            msp.add_text(text, height=h, dxfattribs={**attribs, "insert": (x, y)})
    if np.all(lo <= hi):
        # Document.update_extents copies these into $EXTMIN/$EXTMAX on write.
        msp.dxf.extmin = (lo[0], lo[1], 0.0)
        msp.dxf.extmax = (hi[0], hi[1], 0.0)
    return doc


def dxf_text(layers) -> str:
    """The DXF file of the layers as ezdxf writes :func:`build_dxf`'s drawing, the same text for the same layers.

    ezdxf stamps the creation and update times and random GUIDs into a drawing;
    its option ``write_fixed_meta_data_for_testing`` (made for comparing files)
    fixes them, and the CLASSES section is put in an order that does not
    follow the hash seed (:func:`_canonical_classes`). Handles are given in
    order, so the file depends on the layers alone.
    """
    doc = build_dxf(layers)
    with _fixed_metadata():
        _canonical_classes(doc)
        stream = io.StringIO()
        doc.write(stream)
    return stream.getvalue()


def clean_path(vertices, bulges, tol: float | None = None):
    """Drop segments of a closed bulge path that are no longer than ``tol`` (default :func:`min_spacing`).

    A short segment's start vertex is removed, so the previous segment ends
    where the short one ended: the path moves by at most ``tol``.

    Returns
    -------
    (M, 2) vertices, (M,) bulges

    Raises
    ------
    ValueError
        If fewer than 2 segments remain, or coordinates are not finite.
    """
    v = np.asarray(vertices, dtype=np.float64)
    b = np.asarray(bulges, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise ValueError("path has non-finite coordinates")
    tol = min_spacing(v) if tol is None else tol
    while len(v) >= 2:
        step = np.hypot(*(np.roll(v, -1, axis=0) - v).T)
        short = step <= tol
        if not short.any():
            break
        # drop every other short one so neighbours of the removed vertex are re-measured
        k = np.nonzero(short)[0]
        k = k[np.concatenate(([True], np.diff(k) > 1))]
        keep = np.ones(len(v), dtype=bool)
        keep[k] = False
        v, b = v[keep], b[keep]
    if len(v) < 2:
        raise ValueError(f"path has {len(v)} distinct vertices, needs at least 2")
    return v, b


@contextlib.contextmanager
def _fixed_metadata():
    """ezdxf stamps times and random GUIDs into new and written documents;
    fixed values make the same design give byte-identical files."""
    import ezdxf

    saved = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        yield
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = saved


def write_dxf(path: str | os.PathLike, layers) -> None:
    """Write the layers to an ASCII DXF R2010 file, atomically: :func:`dxf_text`.

    Parameters
    ----------
    path : str or path-like
        Output file; the folder is created if missing.
    layers : iterable of DxfLayer
        See :func:`build_dxf`.

    Raises
    ------
    ValueError
        As :func:`prepare` (nothing is written).
    OutputError
        When the file cannot be written (``path`` is then unchanged).
    """
    text = dxf_text(layers)
    atomic_write(path, text.encode("utf-8"))


def _canonical_classes(doc) -> None:
    """Put the CLASSES section in an order that does not depend on the hash seed.

    ezdxf adds the version's required classes in a fixed order, then one
    class per entity type in use, iterating a *set* of type names: the order
    of e.g. ``LAYOUT`` and ``ACDBPLACEHOLDER`` followed ``PYTHONHASHSEED``, so
    the same design gave different bytes in different processes. Adding the
    classes now and sorting the set-derived ones by name makes the later
    ``add_required_classes`` inside ``doc.write`` a no-op (it only adds
    missing keys) and the file byte-reproducible.
    """
    from ezdxf.sections.classes import REQ_R2004, REQUIRED_CLASSES

    section = doc.classes
    section.add_required_classes(doc.dxfversion)
    fixed = REQUIRED_CLASSES.get(doc.dxfversion, REQ_R2004)
    items = list(section.classes.items())
    head = [kv for name in fixed for kv in items if kv[1].dxf.name == name]
    rest = sorted((kv for kv in items if kv not in head), key=lambda kv: kv[0])
    section.classes = OrderedDict(head + rest)


def _readfile(path):
    import ezdxf

    try:
        return ezdxf.readfile(path)
    except OSError as exc:
        raise InputFileError(f"{path}: cannot read DXF file ({exc.strerror or exc})") from exc
    except ezdxf.DXFError as exc:
        raise InputFileError(f"{path}: not a valid DXF file ({exc})") from exc


def read_dxf(path: str | os.PathLike) -> dict:
    """Read back a DXF file written by :func:`write_dxf`.

    Parameters
    ----------
    path : str or path-like
        DXF file.

    Returns
    -------
    dict
        ``{layer_name: {"outlines": [(N, 2) float64 arrays], "circles":
        [(cx, cy, r)], "paths": [((N, 2) vertices, (N,) bulges)], "texts":
        [(x, y, height, str)]}}`` in file order (polylines with any non-zero
        bulge are paths, the others outlines), for every layer that holds an entity
        and every layer of the layer table other than ``0`` and
        ``Defpoints`` (so empty layers round-trip too).

    Raises
    ------
    InputFileError
        When the file cannot be read or holds something the writer never
        writes (open polylines, widths, other entity types):
        silently dropping such entities would hide a broken export.
    """
    doc = _readfile(path)
    out: dict = {}
    for layer in doc.layers:
        if layer.dxf.name.lower() not in ("0", "defpoints"):
            out[layer.dxf.name] = _empty()
    for e in doc.modelspace():
        kind = e.dxftype()
        name = e.dxf.layer
        where = f"{path}: {kind} #{e.dxf.handle} on layer {name}"
        entry = out.setdefault(name, _empty())
        if kind == "LWPOLYLINE":
            values = e.lwpoints.values
            if not e.closed:
                raise InputFileError(f"{where} is not closed (outlines must be closed)")
            if np.any(values[:, 2:4] != 0):
                raise InputFileError(f"{where} has widths (outlines must be plain lines and arcs)")
            if np.any(values[:, 4] != 0):
                entry["paths"].append(
                    (np.array(values[:, :2], dtype=np.float64), np.array(values[:, 4], dtype=np.float64))
                )
            else:
                entry["outlines"].append(np.array(values[:, :2], dtype=np.float64))
        elif kind == "CIRCLE":
            c = e.dxf.center
            entry["circles"].append((float(c.x), float(c.y), float(e.dxf.radius)))
        elif kind == "TEXT":
            p = e.dxf.insert
            entry["texts"].append((float(p.x), float(p.y), float(e.dxf.height), e.dxf.text))
        else:
            raise InputFileError(f"{where} is not supported (only closed LWPOLYLINE, CIRCLE and TEXT)")
    return out


def _empty() -> dict:
    return {"outlines": [], "circles": [], "paths": [], "texts": []}


def audit_dxf(path: str | os.PathLike) -> int:
    """Number of errors ezdxf's auditor finds in a DXF file.

    Parameters
    ----------
    path : str or path-like
        DXF file.

    Returns
    -------
    int
        ``len(doc.audit().errors)``; 0 for a clean file. (Problems the
        auditor repaired itself are ``fixes``, not counted here.)

    Raises
    ------
    InputFileError
        When the file cannot be read or parsed at all.
    """
    return len(_readfile(path).audit().errors)
