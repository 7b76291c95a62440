"""The part set's file formats by name: what each is written from and its writer, so the part set's files are one
loop over the chosen formats (``wgcad parts --formats``) with no branch per format.

A format is written from one of the things a part provides: its ``drawing`` (the DXF layers with the title
block), its ``mesh`` (STL) or its ``solid`` (the STEP text of its OpenCASCADE solid), one file per part; or from
the whole ``set`` of meshes (3MF: the parts side by side in one file, each deformed assembly in its own).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .dxf import write_dxf
from .stl import write_stl
from .svg import write_svg
from .threemf import exploded, write_3mf

__all__ = ["FileFormat", "Drawing", "FORMATS"]


@dataclass(frozen=True, slots=True)
class Drawing:
    """A part's drawing: its layers (title block last) and the title an SVG carries."""

    layers: list
    title: str


@dataclass(frozen=True, slots=True)
class FileFormat:
    """One file format of the part set.

    Attributes
    ----------
    name : str
        The word of ``--formats`` and the files' suffix.
    source : str
        What it is written from: "drawing", "mesh" or "solid" (one file per part that has it), or "set" (the
        whole set's meshes).
    write : callable
        ``write(path, item)`` for a part's item; for a "set" format ``write(target, stem, parts, meshes)``, with
        ``target(name)`` the temporary path of the file ``name`` and ``meshes`` every part's mesh by name.
    """

    name: str
    source: str
    write: Callable


def _dxf(path, drawing: Drawing) -> None:
    write_dxf(path, drawing.layers)


def _svg(path, drawing: Drawing) -> None:
    write_svg(path, drawing.layers, drawing.title)


def _step(path, text: bytes) -> None:
    Path(path).write_bytes(text)


def _3mf(target, stem: str, parts: list, meshes: dict) -> None:
    # the parts side by side (once: assembled at the origin they shared 1234 mm^3, which a slicer takes for
    # intersecting objects); the deformed assemblies stay assembled, each in its own file: that is what they show
    own = {p.name: meshes[p.name] for p in parts if not p.name.startswith("assembly")}
    write_3mf(target(f"{stem}_parts.3mf"), own, exploded(own))
    for p in parts:
        if p.name.startswith("assembly"):
            write_3mf(target(f"{stem}_{p.name}.3mf"), {f"{p.name}_{k}": m for k, m in p.member_meshes().items()})


#: every format of the part set, in the order ``wgcad parts`` writes and lists them
FORMATS = {
    f.name: f
    for f in (
        FileFormat("dxf", "drawing", _dxf),
        FileFormat("svg", "drawing", _svg),
        FileFormat("stl", "mesh", write_stl),
        FileFormat("3mf", "set", _3mf),
        FileFormat("step", "solid", _step),
    )
}
