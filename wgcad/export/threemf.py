"""3MF export and read-back (one object per part, millimetre units), byte-reproducible: plain zip + XML, no extra library."""

from __future__ import annotations

import io
import os
import zipfile
from xml.etree import ElementTree as ET

import numpy as np

from wgcad.atomic import atomic_write
from wgcad.errors import InputFileError

__all__ = ["threemf_bytes", "write_3mf", "read_3mf"]

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


def _model_xml(meshes: dict) -> str:
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
    out.extend(f'<item objectid="{k}"/>' for k in range(1, len(meshes) + 1))
    out.append("</build></model>\n")
    return "\n".join(out)


def threemf_bytes(meshes: dict) -> bytes:
    """The 3MF package of named meshes ``{name: Mesh}`` (mm), one object and one build item each."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name, text in (
            ("[Content_Types].xml", CONTENT_TYPES),
            ("_rels/.rels", RELS),
            ("3D/3dmodel.model", _model_xml(meshes)),
        ):
            info = zipfile.ZipInfo(name, date_time=ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, text.encode("utf-8"))
    return buf.getvalue()


def write_3mf(path: str | os.PathLike, meshes: dict) -> None:
    """Write named meshes to a 3MF file, atomically."""
    atomic_write(path, threemf_bytes(meshes))


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
    for obj in root.iter(q + "object"):
        verts = np.array([[float(v.get(a)) for a in "xyz"] for v in obj.iter(q + "vertex")], dtype=np.float64)
        tris = np.array([[int(t.get(a)) for a in ("v1", "v2", "v3")] for t in obj.iter(q + "triangle")], dtype=np.int64)
        objects[obj.get("name") or obj.get("id")] = (verts.reshape(-1, 3), tris.reshape(-1, 3))
    return {"unit": root.get("unit", "millimeter"), "objects": objects}
