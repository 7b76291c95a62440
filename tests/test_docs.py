"""The project's own documentation: every model citation in the code names a section of docs/models.md, sources and links resolve."""

import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
MODELS = DOCS / "models.md"

#: the numbering models.md keeps (the handbook's, so citations can be rewritten mechanically)
REQUIRED_SECTIONS = {
    "1",
    "2",
    "2.1",
    "2.2",
    "2.3",
    "3",
    "3.1",
    "3.2",
    "3.3",
    "3.4",
    "3.5",
    "3.6",
    "4",
    "4.1",
    "5",
    "6",
    "6.1",
    "6.2",
    "7",
    "8",
    "9",
}

_NUM = r"\d+(?:\.\d+)*"
#: "docs/models.md 3.3", "theory.md 2.1, 2.2", "theory.md 2.2 and 9", "theory.md section 9"
CITATION = re.compile(
    rf"(?:docs/models\.md|theory\.md)\s+(?:(?:sections?|sec\.?)\s+)?({_NUM}(?:\s*(?:,|and|&)\s*{_NUM})*)"
)


def model_sections(text: str) -> set[str]:
    """Section numbers of the Markdown headings ``## 3.`` / ``### 3.1 ...``."""
    return {m.group(1) for m in re.finditer(rf"^#{{2,4}}\s+({_NUM})\.?\s", text, flags=re.M)}


def cited_sections(text: str) -> list[str]:
    """Every section number cited in ``text``."""
    out = []
    for m in CITATION.finditer(text):
        out += re.findall(_NUM, m.group(1))
    return out


def _sources():
    files = sorted((ROOT / "wgcad").rglob("*.py")) + sorted((ROOT / "templates").rglob("*.toml"))
    files += sorted((ROOT / "benchmarks").glob("*.py"))
    return files


def test_citation_parser_reads_every_form():
    text = (
        "# docs/models.md 3.3, section I\n"
        '"""Whole gear (theory.md 2.1, 2.2)."""\n'
        "# D1 (theory.md 2.2 and 9): rho\n"
        "# inputs from theory.md section 9. x\n"
        "# v' = -w (theory.md 3.1; dtheta)\n"
        "# theory.md 1, [S3 eq. 21-24] and theory.md 5, 7.\n"
        "# not a citation: theory of rings 4.7\n"
    )
    assert cited_sections(text) == ["3.3", "2.1", "2.2", "2.2", "9", "9", "3.1", "1", "5", "7"]


def test_models_keeps_the_handbook_numbering():
    found = model_sections(MODELS.read_text(encoding="utf-8"))
    assert REQUIRED_SECTIONS <= found, f"missing sections: {sorted(REQUIRED_SECTIONS - found)}"


def test_every_citation_names_an_existing_section():
    sections = model_sections(MODELS.read_text(encoding="utf-8"))
    bad, count = [], 0
    for path in _sources():
        for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for sec in cited_sections(line):
                count += 1
                if sec not in sections:
                    bad.append(f"{path.relative_to(ROOT)}:{lineno}: section {sec}")
    assert count > 50, "the scan found (almost) no citations: is the pattern still right?"
    assert not bad, "citations of sections docs/models.md does not have:\n" + "\n".join(bad)


def test_a_citation_of_a_missing_section_is_caught(tmp_path):
    sections = model_sections(MODELS.read_text(encoding="utf-8"))
    assert [s for s in cited_sections("# docs/models.md 3.7, 3.3") if s not in sections] == ["3.7"]


def test_every_source_cited_in_models_is_in_the_bibliography():
    models = MODELS.read_text(encoding="utf-8")
    bib = (DOCS / "bibliography.md").read_text(encoding="utf-8")
    cited = set(re.findall(r"\bS(\d)\b", " ".join(re.findall(r"\[S[^\]]*\]", models))))
    defined = set(re.findall(r"^- \*\*\[S(\d)\]\*\*", bib, flags=re.M))
    assert cited and cited <= defined, f"undefined sources: {sorted(cited - defined)}"


@pytest.mark.parametrize("doc", ["README.md", "models.md", "bibliography.md"])
def test_relative_links_resolve(doc):
    text = (DOCS / doc).read_text(encoding="utf-8")
    links = [t for t in re.findall(r"\]\(([^)#\s]+)\)", text) if "://" not in t]
    for target in links:
        assert (DOCS / target).exists(), f"{doc}: broken link {target}"


def test_licence_is_mit_as_pyproject_says():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert meta["project"]["license"] == "MIT"
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License")
    assert "Copyright (c) 2026 the wgcad developers" in text
    assert 'THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND' in text
