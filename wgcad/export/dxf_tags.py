"""The DXF R2010 text of prepared layers, written without ezdxf.

ezdxf costs 0.13 s to import and 0.16 s to write a gear's two 9,000-vertex
outlines (most of a ``generate``); the file it writes is an empty drawing's
fixed sections with the layers, linetype, entities, extents and handles
filled in. This module keeps that empty drawing (:mod:`wgcad.export.dxf_skeleton`,
made from ezdxf's own output by tests/dxf_skeleton_make.py) and fills the
same places the way ezdxf does, handles given in the same order, so the file
is ezdxf's byte for byte (tests/test_dxf_writer.py compares every
template's drawings and random ones; ezdxf reads the files back in the tests).
"""

from __future__ import annotations

from wgcad.export import dxf_skeleton as sk

__all__ = ["dxf_text", "CENTER_PATTERN", "CENTER_DESCRIPTION"]

#: The CENTER linetype of construction layers: ISO-style long dash, gap, short dash, gap (mm; total length first).
CENTER_PATTERN = (20.0, 12.0, -3.0, 2.0, -3.0)
CENTER_DESCRIPTION = "Center ____ _ ____ _"

#: The CENTER linetype as ezdxf writes it.
_CENTER = (
    "  0\nLTYPE\n  5\n{handle}\n330\n{table}\n100\nAcDbSymbolTableRecord\n100\nAcDbLinetypeTableRecord\n"
    "  2\nCENTER\n 70\n0\n  3\n{description}\n 72\n65\n 73\n{n}\n 40\n{total}\n{elements}"
)


def _layer_record(handle: str, name: str, color: int, linetype: str, plot, plotstyle: str, material) -> str:
    text = (
        f"  0\nLAYER\n  5\n{handle}\n330\n{sk.LAYER_TABLE}\n100\nAcDbSymbolTableRecord\n100\nAcDbLayerTableRecord\n"
        f"  2\n{name}\n 70\n0\n 62\n{color}\n  6\n{linetype}\n"
    )
    if plot is not None:
        text += f"290\n{plot}\n"
    text += f"370\n-3\n390\n{plotstyle}\n"
    if material is not None:
        text += f"347\n{material}\n"
    return text


def _entity(kind: str, handle: int, layer: str, subclass: str) -> str:
    return f"  0\n{kind}\n  5\n{handle:X}\n330\n{sk.MODEL_SPACE}\n100\nAcDbEntity\n  8\n{layer}\n100\n{subclass}\n"


def _polyline(handle: int, layer: str, xy, bulges=None) -> str:
    head = _entity("LWPOLYLINE", handle, layer, "AcDbPolyline") + f" 90\n{len(xy)}\n 70\n1\n"
    if bulges is None:
        return head + "".join([f" 10\n{x!r}\n 20\n{y!r}\n" for x, y in xy.tolist()])
    # ezdxf writes a bulge only where it is not zero
    return head + "".join(
        [
            f" 10\n{x!r}\n 20\n{y!r}\n 42\n{b!r}\n" if b else f" 10\n{x!r}\n 20\n{y!r}\n"
            for (x, y), b in zip(xy.tolist(), bulges.tolist())
        ]
    )


def _center_linetype(handle: int) -> str:
    elements = "".join(f" 49\n{float(e)!r}\n 74\n0\n" for e in CENTER_PATTERN[1:])
    return _CENTER.format(
        handle=f"{handle:X}",
        table=sk.LTYPE_TABLE,
        description=CENTER_DESCRIPTION,
        n=len(CENTER_PATTERN) - 1,
        total=repr(float(CENTER_PATTERN[0])),
        elements=elements,
    )


def dxf_text(layers, lo, hi) -> str:
    """The DXF file of prepared layers (:func:`wgcad.export.dxf.prepare`) and their bounding box.

    Handles are given as ezdxf gives them in :func:`wgcad.export.dxf.build_dxf`:
    per layer its table record, then the CENTER linetype (first construction
    layer), then its outlines, paths, circles and texts; then the two
    application ids and the dictionary variable ezdxf adds when it writes.
    """
    handle = sk.FIRST_HANDLE
    records = {name.lower(): [h, name, 7, "Continuous", plot, style, mat] for h, name, plot, style, mat in sk.LAYERS}
    material = sk.LAYERS[0][4]
    plotstyle = sk.LAYERS[0][3]
    ltype_extra = ""
    entities = []
    for layer in layers:
        key = layer.name.lower()
        if key not in records:
            records[key] = [f"{handle:X}", layer.name, layer.color, "Continuous", None, plotstyle, material]
            handle += 1
        else:
            records[key][2] = layer.color
        if layer.construction:
            if not ltype_extra:
                ltype_extra = _center_linetype(handle)
                handle += 1
            records[key][3] = "CENTER"
            records[key][4] = "0"
        for pts in layer.outlines:
            entities.append(_polyline(handle, layer.name, pts))
            handle += 1
        for v, b in layer.paths:
            entities.append(_polyline(handle, layer.name, v, b))
            handle += 1
        for cx, cy, r in layer.circles:
            entities.append(
                _entity("CIRCLE", handle, layer.name, "AcDbCircle")
                + f" 10\n{cx!r}\n 20\n{cy!r}\n 30\n0.0\n 40\n{r!r}\n"
            )
            handle += 1
        for x, y, h, text in layer.texts:
            entities.append(
                _entity("TEXT", handle, layer.name, "AcDbText")
                + f" 10\n{x!r}\n 20\n{y!r}\n 30\n0.0\n 40\n{h!r}\n  1\n{text}\n100\nAcDbText\n"
            )
            handle += 1
    if lo[0] <= hi[0] and lo[1] <= hi[1]:
        low = (repr(float(lo[0])), repr(float(lo[1])), "0.0")
        high = (repr(float(hi[0])), repr(float(hi[1])), "0.0")
    else:  # nothing measured: ezdxf's "no extents"
        low, high = ("1e+20",) * 3, ("-1e+20",) * 3
    values = {
        "LTYPE_COUNT": str(sk.LTYPES + bool(ltype_extra)),
        "LTYPE_EXTRA": ltype_extra,
        "LAYER_COUNT": str(len(records)),
        "LAYER_RECORDS": "".join(_layer_record(*r) for r in records.values()),
        "ENTITIES": "".join(entities),
        "APPID_HATCH": f"{handle:X}",
        "APPID_EZDXF": f"{handle + 1:X}",
        "WRITTEN_BY": f"{handle + 2:X}",
        "DICTVAR": f"{handle + 2:X}",
        "HANDSEED": f"{handle + 3:X}",
    }
    for prefix in ("", "LAYOUT_"):
        for axis, a, b in zip("XYZ", low, high):
            values[f"{prefix}EXTMIN_{axis}"] = a
            values[f"{prefix}EXTMAX_{axis}"] = b
    out = [sk.PARTS[0]]
    for name, part in zip(sk.SLOTS, sk.PARTS[1:]):
        out.append(values[name])
        out.append(part)
    return "".join(out)
