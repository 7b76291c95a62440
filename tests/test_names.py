"""One name, one meaning (issue 43): each free-play and torque figure has its own JSON key in one command's output
only; the resolution and validity of a figure travel with it into text, JSON and page; every page links the
glossary that defines the names (docs/glossary.md)."""

from __future__ import annotations

import contextlib
import html
import io
import json
import re

import pytest
from conftest import ROOT, TEMPLATES

from wgcad.cli import main
from wgcad.design.bolting import choose_bolts

#: the quantities that had one name for several figures: any key naming one of them
NAMED = ("backlash", "lost_motion", "free_play", "windup_offset", "rated_torque", "design_torque")


def _keys(doc) -> set[str]:
    """Every key of a JSON document, nested ones too (their own names, not paths)."""
    out = set()
    if isinstance(doc, dict):
        for k, v in doc.items():
            out.add(k)
            out |= _keys(v)
    elif isinstance(doc, list):
        for v in doc:
            out |= _keys(v)
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("names")
    out = {}
    for name, args in (
        ("audit", ["audit", str(TEMPLATES / "d1_involute.toml"), "--step-deg", "2"]),
        ("rating", ["rating", str(TEMPLATES / "d1_involute.toml")]),
        ("ke", ["ke", str(TEMPLATES / "d2_imperfect.toml"), "--per-mesh", "4"]),
    ):
        buf = io.StringIO()
        js, page = tmp / f"{name}.json", tmp / f"{name}.html"
        with contextlib.redirect_stdout(buf):
            code = main([*args, "--json", str(js), "--html", str(page)])
        assert code in (0, 1), name
        out[name] = (json.loads(js.read_text()), page.read_text(encoding="utf-8"), buf.getvalue())
    return out


def test_each_named_quantity_has_its_key_in_one_command_only(runs):
    owner = {}
    for cmd, (doc, _, _) in runs.items():
        for k in _keys(doc):
            if any(n in k for n in NAMED):
                owner.setdefault(k, set()).add(cmd)
    shared = {k: sorted(v) for k, v in owner.items() if len(v) > 1}
    assert not shared, shared
    # each command names its own figure, and the names do not cross: backlash is the audit's free play only
    assert "backlash_arcmin" in _keys(runs["audit"][0]) and "backlash_arcmin" not in _keys(runs["rating"][0])
    assert runs["rating"][0]["windup_offset_arcmin"] > 0 and runs["rating"][0]["lost_motion_at_nm"] > 0
    assert not any("lost_motion" in k for k in _keys(runs["ke"][0])) and "free_play_arcsec" in runs["ke"][0]
    # "rated torque" is the datasheet's only: the audit and the KE do not use the word for the design's [load] value
    for cmd in ("audit", "ke"):
        assert not any("rated" in k for k in _keys(runs[cmd][0])), cmd


def test_the_text_and_the_page_use_the_same_names(runs):
    doc, page, out = runs["rating"]
    assert "wind-up offset (the stiffness fit's intercept" in out and "backlash (free play" not in out
    assert "wind-up offset, lost motion" in page
    assert f"{doc['windup_offset_arcmin']:.2f} arcmin" in out
    assert re.search(r"^  backlash: [0-9.]+ arcmin", runs["audit"][2], flags=re.M)
    assert "free play between the flanks" in runs["ke"][2] and "free play between the flanks" in runs["ke"][1]


def test_the_parts_bolts_are_sized_for_the_design_torque_not_a_rated_one():
    c = choose_bolts(3000.0, 30.0, 81.0, "cup")
    assert "x the design torque 3000 N m" in c.text(3000.0) and "rated" not in c.text(3000.0)


def test_the_rating_stdout_carries_each_limits_bisection_bracket(runs):
    doc, page, out = runs["rating"]
    bracketed = {k: v for k, v in doc["criteria"].items() if v.get("limit_bracket_nm")}
    assert bracketed, "no criterion carries its bisection bracket"
    for k, v in bracketed.items():
        lo, hi = v["limit_bracket_nm"]
        assert lo <= v["limit_torque_nm"] <= hi, k
        line = next(line for line in out.splitlines() if line.strip().startswith(k + " "))
        assert f"{v['limit_torque_nm']:.0f} (in {lo:.0f} .. {hi:.0f}, bisected to " in line, line
        assert f"between {lo:.0f} (met) and {hi:.0f} N m (failed)" in page, k


def test_the_ke_validity_note_is_in_the_json_and_the_page(runs):
    doc, page, out = runs["ke"]
    notes = doc["validity_notes"]
    # d2_imperfect's teeth interfere somewhere over the revolution: the linear model's note applies
    assert doc["free_play_arcsec"]["min"] < 0 and any("the teeth interfere" in n for n in notes)
    for n in notes:
        assert n in out and html.escape(n) in page


def test_every_page_links_the_glossary(runs):
    assert (ROOT / "docs" / "glossary.md").is_file()
    for cmd, (_, page, _) in runs.items():
        assert "<a href='docs/glossary.md'>" in page, cmd
    text = (ROOT / "docs" / "glossary.md").read_text()
    for term in ("backlash", "lost motion", "wind-up offset", "rated torque", "design torque", "entry gap", "KE"):
        assert f"**{term}" in text, term
