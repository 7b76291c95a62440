"""The audit as a library call (wgcad.services.audit_report.audit_document) gives the CLI's document and verdict.

Issue 20: the 3D check, the baseline comparison and the NOT CHECKED notes were wired in the CLI, so a
library user of run_audit got none of them.
"""

from __future__ import annotations

import json

from conftest import TEMPLATES

from wgcad.audit import RunSettings
from wgcad.cli import main
from wgcad.regression import load_baseline
from wgcad.services.audit_report import audit_document

D4 = TEMPLATES / "d4_discrete.toml"


def _strip(doc):
    doc = json.loads(json.dumps(doc))
    doc.pop("elapsed_s", None)
    for pair in doc.get("fcl", {}).get("pairs", []):
        pair.pop("timing_ms", None)
    doc.get("fcl", {}).pop("timing_ms", None)
    return doc


def test_library_document_equals_the_cli_json(tmp_path):
    out = tmp_path / "a.json"
    base = tmp_path / "base.json"
    code = main(["audit", str(D4), "--step-deg", "2", "--engine", "both", "--json", str(out), "--quiet"])
    assert main(["audit", str(D4), "--step-deg", "2", "--write-baseline", str(base), "--quiet"]) == code
    run = audit_document(D4, RunSettings(step_deg=2.0), engine="both")
    assert _strip(run.doc) == _strip(json.loads(out.read_text()))
    assert run.failed == (code == 1)
    assert "fcl" in run.doc and run.doc["not_checked"] == json.loads(out.read_text())["not_checked"]
    # against its own baseline: no drift
    again = audit_document(D4, RunSettings(step_deg=2.0), baseline=load_baseline(base), baseline_path=base)
    assert again.drifts == [] and again.doc["baseline"]["drifts"] == []


def test_library_document_says_what_it_did_not_check():
    # D4 sectored: the audit uses the plain rigid gear, and says so in the document as the CLI does
    run = audit_document(TEMPLATES / "d4_sectored.toml", RunSettings(step_deg=3.0, refine=False))
    assert any("[sectors]" in n for n in run.doc["not_checked"])


def test_settings_errors_name_the_field_in_the_library_and_the_flag_in_the_cli(capsys):
    import pytest

    from wgcad.errors import DesignError

    with pytest.raises(DesignError) as e:
        RunSettings(step_deg=0.0).check()
    assert e.value.field == "step_deg"
    with pytest.raises(DesignError) as e:  # more turns of a perfect drive: refused inside the run
        audit_document(D4, RunSettings(turns=2))
    assert e.value.field == "turns"
    # the flag's bound is the setting's (wgcad/cli/bounds.py): refused while parsing, exit 2, naming the flag
    with pytest.raises(SystemExit) as ex:
        main(["audit", str(D4), "--step-deg", "0.00001"])
    assert ex.value.code == 2
    err = capsys.readouterr().err
    assert "--step-deg" in err and "step_deg" not in err


def test_ke_as_a_library_call_gives_the_cli_document(tmp_path):
    # issue 20: the KE's document and summary were built inside cmd_ke; wgcad.services.ke is the library call
    from wgcad.design import load_design
    from wgcad.drive import build_drive
    from wgcad.placement.imperfect import Imperfections
    from wgcad.services.ke import no_load

    path = TEMPLATES / "d2_imperfect.toml"
    out = tmp_path / "ke.json"
    assert main(["ke", str(path), "--per-mesh", "4", "--json", str(out)]) == 0
    design = load_design(path)
    run, lines = no_load(build_drive(design), Imperfections.from_spec(design.imperfections), 4, str(path))
    assert run.doc == json.loads(out.read_text())
    assert lines[0].startswith(design.drive.name) and "largest KE" in lines[2]


def test_library_files_equal_the_clis(tmp_path):
    # the files of `wgcad audit` from a library call: the baseline and the pictures byte-identical to the CLI's
    from wgcad.export.files.audit import plot_paths, write_audit_files
    from wgcad.services.audit_report import baseline_document

    cli = tmp_path / "cli"
    cli.mkdir()
    args = ["audit", str(D4), "--step-deg", "2", "--quiet"]
    code = main(
        args + ["--write-baseline", str(cli / "b.json"), "--plot", str(cli / "p.png"), "--json", str(cli / "a.json")]
    )
    rs = RunSettings(step_deg=2.0)
    run = audit_document(D4, rs, plot=True)
    lib = tmp_path / "lib"
    files = write_audit_files(
        run,
        json_path=lib / "a.json",
        baseline=baseline_document(run, rs, str(D4)),
        baseline_path=lib / "b.json",
        plot=lib / "p.png",
    )
    names = ["a.json", "b.json"] + [p.name for _, p in plot_paths(lib / "p.png")]
    assert [p.name for p in files] == names and sorted(p.name for p in lib.iterdir()) == sorted(names)
    for name in names[1:]:
        assert (lib / name).read_bytes() == (cli / name).read_bytes(), name
    assert _strip(json.loads((lib / "a.json").read_text())) == _strip(json.loads((cli / "a.json").read_text()))
    assert run.failed == (code == 1)
