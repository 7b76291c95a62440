"""README.md's TOML excerpts hold the values of the files they quote (issue 43: its excerpt of d1_involute.toml said
ccw, addendum_coef 1.0 and w0_coef 1.1 where the file says cw, 0.55 and 0.97625)."""

import re
import tomllib

import pytest
from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")
#: a ```toml block and the paragraph before it, which names the file it quotes ("Excerpt of `templates/X.toml`")
_BLOCK = re.compile(r"((?:[^\n]+\n){1,4})\n?```toml\n(.*?)```", re.S)
_QUOTED = re.compile(r"[Ee]xcerpt of `((?:templates/)[\w/.-]+\.toml)`")


def _excerpts():
    out = []
    for before, body in _BLOCK.findall(README):
        m = _QUOTED.search(before)
        if m:
            out.append((m.group(1), body))
    return out


def test_the_readme_quotes_at_least_one_template():
    assert any(path == "templates/d1_involute.toml" for path, _ in _excerpts())


@pytest.mark.parametrize("path,body", _excerpts(), ids=[p for p, _ in _excerpts()])
def test_every_key_of_an_excerpt_has_the_files_value(path, body):
    data = tomllib.loads((ROOT / path).read_text(encoding="utf-8"))
    excerpt = tomllib.loads(body)  # the excerpt itself is valid TOML
    checked = 0
    for table, keys in excerpt.items():
        assert table in data, f"README quotes [{table}], which {path} has not"
        for key, value in keys.items():
            assert key in data[table], f"README quotes [{table}] {key}, which {path} has not"
            assert data[table][key] == value, f"README: [{table}] {key} = {value!r}; {path}: {data[table][key]!r}"
            checked += 1
    assert checked >= 5
