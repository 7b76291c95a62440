"""FreeCAD macro: a wgcad design file's part set placed in a FreeCAD document as solids, with their gear data in
properties.

It runs ``wgcad parts DESIGN --format step --json`` (wgcad's own environment: FreeCAD's Python never imports wgcad or
its OpenCASCADE), reads every part's STEP file with FreeCAD's ``Part.read`` and adds it as a ``Part::Feature`` named
after the part, whose properties (group ``wgcad``) hold the part's entry of ``DESIGN_parts.json``: volume and the
bound it is known to, sizes, kind, and the gear data (teeth, module, diameters, span or pins), nested keys joined
with ``_``. Headless::

    WGCAD_DESIGN=templates/d1_involute.toml WGCAD_FCSTD=d1.FCStd freecadcmd freecad/wgcad_parts.py

``WGCAD`` is the command that runs wgcad (default ``wgcad`` on the PATH, e.g. ``/path/to/.venv/bin/wgcad``). In the
FreeCAD GUI (Macro > Macros...) without ``WGCAD_DESIGN`` it asks for the design file and fills the active document
(a new one if none). From FreeCAD's Python console: ``import wgcad_parts; wgcad_parts.place("design.toml")``.
"""

import json
import os
import shlex
import subprocess
import tempfile

import FreeCAD
import Part

GROUP = "wgcad"


def run_wgcad(design: str, out: str) -> dict:
    """The parts JSON of ``wgcad parts`` run on ``design`` with STEP files written into ``out``."""
    cmd = shlex.split(os.environ.get("WGCAD", "wgcad"))
    res = subprocess.run(
        [*cmd, "parts", design, "--out", out, "--format", "step", "--json"], capture_output=True, text=True
    )
    if res.returncode != 0:
        raise RuntimeError(f"wgcad parts failed (exit {res.returncode}): {res.stderr.strip()}")
    return json.loads(res.stdout)


def _flat(prefix: str, value):
    """``(name, value)`` pairs of a JSON value, nested keys joined with ``_`` (lists kept as JSON text)."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _flat(f"{prefix}_{k}" if prefix else k, v)
    elif value is not None:
        yield prefix, value


def _add_property(obj, name: str, value) -> None:
    name = "".join(c if c.isalnum() else "_" for c in name)
    if isinstance(value, bool):
        kind, value = "App::PropertyBool", value
    elif isinstance(value, int):
        kind = "App::PropertyInteger"
    elif isinstance(value, float):
        kind = "App::PropertyFloat"
    elif isinstance(value, str):
        kind = "App::PropertyString"
    else:
        kind, value = "App::PropertyString", json.dumps(value)
    obj.addProperty(kind, name, GROUP, "from wgcad's parts JSON")
    setattr(obj, name, value)


def place(design: str, doc=None):
    """Place the part set of ``design`` in ``doc`` (default the active document, or a new one); returns the
    document. Each part is one ``Part::Feature`` named after it with its figures as properties."""
    doc = doc or FreeCAD.ActiveDocument or FreeCAD.newDocument("wgcad")
    design = os.path.abspath(design)
    with tempfile.TemporaryDirectory() as out:
        report = run_wgcad(design, out)
        stem = os.path.splitext(os.path.basename(design))[0]
        for name, entry in report["parts"].items():
            path = os.path.join(out, f"{stem}_{name}.step")
            if not os.path.exists(path):
                continue  # a deformed assembly: meshes only
            shape = Part.read(path)
            obj = doc.addObject("Part::Feature", name)
            obj.Shape = shape
            _add_property(obj, "design", design)
            for key, value in _flat("", entry):
                _add_property(obj, key, value)
    doc.recompute()
    return doc


def main() -> None:
    design = os.environ.get("WGCAD_DESIGN")
    if design is None and FreeCAD.GuiUp:
        from PySide import QtGui

        design, _ = QtGui.QFileDialog.getOpenFileName(None, "wgcad design file", "", "TOML (*.toml)")
    if not design:
        raise SystemExit("wgcad_parts: no design file (set WGCAD_DESIGN)")
    doc = place(design)
    target = os.environ.get("WGCAD_FCSTD")
    if target:
        doc.saveAs(os.path.abspath(target))
        print(f"wgcad_parts: {len(doc.Objects)} parts of {design} saved to {target}")


# a GUI macro runs as __main__; freecadcmd runs a file under its stem's name, as an import would: the design in the
# environment tells the run from an import
if __name__ == "__main__" or os.environ.get("WGCAD_DESIGN"):
    main()
