"""The FreeCAD macro (freecad/wgcad_parts.py), run headless with Debian's freecadcmd: the part set of a design file
placed in a FreeCAD document as valid solids of the volumes the parts JSON states, with the gear data in properties;
the saved document read back by a second FreeCAD run."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import TEMPLATES, edit_toml

pytestmark = pytest.mark.skipif(shutil.which("freecadcmd") is None, reason="FreeCAD (freecadcmd) not installed")
pytest.importorskip("build123d", reason="the CAD extra (build123d) is not installed: pip install 'wgcad[cad]'")

MACRO = Path(__file__).resolve().parents[1] / "freecad" / "wgcad_parts.py"


def test_the_macro_places_the_part_set_with_its_gear_data(tmp_path):
    text = (TEMPLATES / "d4_discrete.toml").read_text()
    design = tmp_path / "small.toml"
    design.write_text(edit_toml(edit_toml(text, "drive", "z_flex", "40"), "drive", "z_rigid", "42"))
    doc = tmp_path / "small.FCStd"
    root = str(Path(__file__).resolve().parents[1])
    env = dict(os.environ, WGCAD=f"{sys.executable} -m wgcad", WGCAD_DESIGN=str(design), WGCAD_FCSTD=str(doc))
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")  # wgcad's run sees this checkout
    res = subprocess.run(["freecadcmd", str(MACRO)], env=env, capture_output=True, text=True, timeout=900)
    assert doc.exists(), res.stdout + res.stderr
    check = tmp_path / "check.py"
    check.write_text(
        "import json, FreeCAD\n"
        f"d = FreeCAD.openDocument({str(doc)!r})\n"
        "for o in d.Objects:\n"
        "    props = {p: getattr(o, p) for p in o.PropertiesList if o.getGroupOfProperty(p) == 'wgcad'}\n"
        "    print('OBJ', json.dumps([o.Name, o.Shape.isValid(), len(o.Shape.Solids), o.Shape.Volume, props]))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "WGCAD_DESIGN"}
    res = subprocess.run(["freecadcmd", str(check)], env=env, capture_output=True, text=True, timeout=900)
    rows = [json.loads(line[4:]) for line in res.stdout.splitlines() if line.startswith("OBJ ")]
    assert [r[0] for r in rows] == ["flexspline", "plug", "rigid"], res.stdout + res.stderr
    for name, valid, solids, volume, props in rows:
        assert valid and solids == 1, name
        bound = props.get("volume_tol_mm3", 1e-9 * props["volume_mm3"]) + 5e-5
        assert abs(volume - props["volume_mm3"]) <= bound, name
        assert props["design"] == str(design)
    flex, rigid = rows[0][4], rows[2][4]
    assert flex["gear_data_teeth"] == 40 and rigid["gear_data_teeth"] == 42
    assert rigid["gear_data_module_mm"] == pytest.approx(0.4) and rigid["bolt_count"] > 0
    assert rigid["gear_data_pins_kind"] == "between pins" and "cup flexspline" in flex["kind"]
