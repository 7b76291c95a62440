"""The README's "Library use" runs as written: every ``python`` block of that section, one after the other in one
namespace (as a reader types them into one session), in a folder holding a copy of the templates; and the
library's records agree with what the CLI writes for the same design."""

import json
import re
import shutil

import pytest
from conftest import ROOT, TEMPLATES

import wgcad
from wgcad.cli import main


def _blocks() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("\n## Library use\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)```", section, flags=re.S)


def test_the_section_has_its_examples():
    blocks = _blocks()
    assert len(blocks) >= 2
    for call in ("wgcad.audit(", "wgcad.load_audit(", "wgcad.kinematic_error(", "wgcad.rating(", "wgcad.parts("):
        assert call in blocks[0], call


def test_the_library_use_examples_run(tmp_path, monkeypatch, capsys):
    shutil.copytree(TEMPLATES, tmp_path / "templates")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for i, block in enumerate(_blocks()):
        exec(compile(block, f"README.md, Library use, block {i + 1}", "exec"), namespace)
    out = capsys.readouterr().out
    assert "interference: False" in out and "rated " in out and "KE " in out
    assert (tmp_path / "output" / "lib_parts" / "d4_discrete_rigid.stl").is_file()
    assert (tmp_path / "output" / "lib" / "d1_involute.dxf").is_file()


def test_the_records_hold_what_the_commands_write(tmp_path, capsys):
    """wgcad.audit's doc is wgcad audit --json's document (the run's timing aside), wgcad.parts' report its
    parts JSON: the library is the CLI's own call, not a second implementation."""
    design = TEMPLATES / "d4_discrete.toml"
    assert main(["audit", str(design), "--json", str(tmp_path / "a.json"), "--quiet"]) == 0
    cli = json.loads((tmp_path / "a.json").read_text())
    lib = json.loads(json.dumps(wgcad.audit(str(design)).doc))
    for doc in (cli, lib):
        doc.pop("elapsed_s", None)
        doc.get("settings", {}).pop("elapsed_s", None)
    assert lib.keys() == cli.keys()
    assert lib["worst"] == cli["worst"] and lib["interference"] == cli["interference"]
    assert main(["parts", str(design), "--out", str(tmp_path / "p"), "--format", "dxf", "--quiet"]) == 0
    cli_parts = json.loads((tmp_path / "p" / "d4_discrete_parts.json").read_text())
    lib_parts = wgcad.parts(design, tmp_path / "q", formats=["dxf"]).report
    assert json.loads(json.dumps(lib_parts))["parts"] == cli_parts["parts"]


@pytest.mark.parametrize("given", ["path", "design", "drive"])
def test_a_design_is_a_path_a_design_or_a_drive(given):
    path = TEMPLATES / "d4_discrete.toml"
    design = wgcad.load_design(path)
    arg = {"path": str(path), "design": design, "drive": wgcad.build_drive(design)}[given]
    run = wgcad.kinematic_error(arg)
    assert run.doc["ke_pp_arcsec"] == wgcad.kinematic_error(path).doc["ke_pp_arcsec"]


def test_a_wrong_design_argument_is_named():
    with pytest.raises(wgcad.errors.DesignError, match="design: expected a design file's path, a Design or a Drive"):
        wgcad.audit(42)


def test_the_modules_audit_and_rating_stay_modules():
    from wgcad.audit import RunSettings

    assert callable(wgcad.audit) and wgcad.audit.RunSettings is RunSettings
    assert callable(wgcad.rating) and wgcad.rating.rate_drive.__module__ == "wgcad.rating.datasheet"
