"""3MF export and read-back (one object per part, millimetre units), byte-reproducible: plain zip + XML, no extra library."""

from __future__ import annotations

import io
import os
import zipfile
from xml.etree import ElementTree as ET

import numpy as np

from wgcad.atomic import atomic_write
from wgcad.errors import InputFileError

__all__ = ["exploded", "threemf_bytes", "write_3mf", "read_3mf"]

NS = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    "</Types>\n"
)
RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    "</Relationships>\n"
)
#: Fixed zip member time (the zip format's earliest), so the same parts give byte-identical files.
ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def exploded(meshes: dict, gap_frac: float = 0.1) -> dict:
    """Build-item offsets ``{name: (dx, dy, dz)}`` (mm) that set the parts side by side along +x, each on z = 0,
    with a gap of ``gap_frac`` of the largest part (at least 5 mm): no two parts share space in a slicer, and each
    object keeps its own coordinates (the offset is the item's transform, not a change of the mesh)."""
    boxes = {n: np.array([np.min(m.vertices, axis=0), np.max(m.vertices, axis=0)]) for n, m in meshes.items()}
    size = max(float(np.max(b[1] - b[0])) for b in boxes.values()) if boxes else 0.0
    gap = max(5.0, gap_frac * size)
    out, x = {}, 0.0
    for n, b in boxes.items():
        out[n] = (x - float(b[0, 0]), -0.5 * float(b[0, 1] + b[1, 1]), -float(b[0, 2]))
        x += float(b[1, 0] - b[0, 0]) + gap
    return out


def _model_xml(meshes: dict, offsets: dict | None = None) -> str:
    out = [
        f'<?xml version="1.0" encoding="UTF-8"?>\n<model unit="millimeter" xml:lang="en-US" xmlns="{NS}">',
        '<metadata name="Application">wgcad</metadata>',
        "<resources>",
    ]
    for k, (name, mesh) in enumerate(meshes.items(), start=1):
        v = np.asarray(mesh.vertices, dtype=np.float64)
        f = np.asarray(mesh.faces, dtype=np.int64)
        out.append(f'<object id="{k}" name="{name}" type="model"><mesh><vertices>')
        # repr of float64: the file keeps full precision (3MF stores decimal text, not float32)
        out.extend(f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in v.tolist())
        out.append("</vertices><triangles>")
        out.extend(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in f.tolist())
        out.append("</triangles></mesh></object>")
    out.append("</resources><build>")
    for k, name in enumerate(meshes, start=1):
        if offsets and name in offsets:
            dx, dy, dz = offsets[name]
            out.append(f'<item objectid="{k}" transform="1 0 0 0 1 0 0 0 1 {dx!r} {dy!r} {dz!r}"/>')
        else:
            out.append(f'<item objectid="{k}"/>')
    out.append("</build></model>\n")
    return "\n".join(out)


def threemf_bytes(meshes: dict, offsets: dict | None = None) -> bytes:
    """The 3MF package of named meshes ``{name: Mesh}`` (mm), one object and one build item each; ``offsets``
    (:func:`exploded`) moves each build item."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name, text in (
            ("[Content_Types].xml", CONTENT_TYPES),
            ("_rels/.rels", RELS),
            ("3D/3dmodel.model", _model_xml(meshes, offsets)),
        ):
            info = zipfile.ZipInfo(name, date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, text.encode("utf-8"))
    return buf.getvalue()


def write_3mf(path: str | os.PathLike, meshes: dict, offsets: dict | None = None) -> None:
    """Write named meshes to a 3MF file, atomically (``offsets``: see :func:`threemf_bytes`)."""
    atomic_write(path, threemf_bytes(meshes, offsets))


def read_3mf(path: str | os.PathLike) -> dict:
    """Read a 3MF file back: ``{"unit": str, "objects": {name: (vertices (n, 3), faces (m, 3))}}``.

    Raises
    ------
    InputFileError
        If the file is not a 3MF package this reader understands.
    """
    try:
        with zipfile.ZipFile(path) as z:
            root = ET.fromstring(z.read("3D/3dmodel.model"))
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as e:
        raise InputFileError(f"{path}: not a readable 3MF file ({e})") from None
    q = f"{{{NS}}}"
    objects = {}
    names = {}
    for obj in root.iter(q + "object"):
        names[obj.get("id")] = obj.get("name") or obj.get("id")
        verts = np.array([[float(v.get(a)) for a in "xyz"] for v in obj.iter(q + "vertex")], dtype=np.float64)
        tris = np.array([[int(t.get(a)) for a in ("v1", "v2", "v3")] for t in obj.iter(q + "triangle")], dtype=np.int64)
        objects[obj.get("name") or obj.get("id")] = (verts.reshape(-1, 3), tris.reshape(-1, 3))
    # each build item's translation (the last three numbers of its 3 x 4 transform; wgcad writes no rotation)
    items = {}
    for it in root.iter(q + "item"):
        m = [float(x) for x in (it.get("transform") or "1 0 0 0 1 0 0 0 1 0 0 0").split()]
        items[names.get(it.get("objectid"), it.get("objectid"))] = tuple(m[9:12])
    return {"unit": root.get("unit", "millimeter"), "objects": objects, "items": items}
