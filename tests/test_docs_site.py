"""The documentation site builds with Sphinx with every warning an error (a broken reference, a docstring numpydoc
cannot parse, a heading out of order, a missing page), and its API reference documents every name of
``wgcad.__all__``."""

import re
import subprocess
import sys

import pytest
from conftest import ROOT

import wgcad

pytest.importorskip("sphinx", reason="the docs extra is not installed: pip install 'wgcad[docs]'")
pytest.importorskip("numpydoc", reason="the docs extra is not installed: pip install 'wgcad[docs]'")
pytest.importorskip("myst_parser", reason="the docs extra is not installed: pip install 'wgcad[docs]'")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    res = subprocess.run(
        [sys.executable, "-m", "sphinx", "-E", "-q", "-W", "--keep-going", "-c", "docs", "-b", "html", ".", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert res.returncode == 0, res.stdout[-4000:] + res.stderr[-4000:]
    assert res.stderr == "", res.stderr
    return out


def test_every_page_is_built(site):
    for page in ("docs/index", "README", "CHANGELOG", "docs/api", "docs/models", "docs/design-keys"):
        assert (site / f"{page}.html").stat().st_size > 5000, page


def test_every_public_name_is_in_the_reference(site):
    api = (site / "docs" / "api.html").read_text(encoding="utf-8")
    ids = set(re.findall(r'<dt class="sig sig-object py" id="([^"]+)"', api))
    missing = [n for n in wgcad.__all__ if n != "__version__" and not ({f"wgcad.{n}", f"wgcad.api.{n}"} & ids)]
    assert not missing, missing
    # and the reference says what they do: the docstring's text is on the page
    assert "The clearance audit over the generator cycle" in api


def test_the_models_page_keeps_its_sections(site):
    models = (site / "docs" / "models.html").read_text(encoding="utf-8")
    heads = re.findall(r"^## (\d+)\.", (ROOT / "docs" / "models.md").read_text(encoding="utf-8"), flags=re.M)
    assert heads and all(f"{h}." in models for h in heads)
