"""The audit's interactive page (`wgcad audit --html`): self-contained, the figures and tables there, and loaded in a
real headless browser (Debian's chromium) with no console message and every figure drawn (issue 23)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import pytest
from conftest import TEMPLATES

from wgcad.cli import main

CASES = ["d4_discrete", "d2_imperfect"]  # a perfect drive, and one with errors (every passage's entry gap)


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    out = {}
    for name in CASES:
        d = tmp_path_factory.mktemp(name)
        page, doc = d / "audit.html", d / "audit.json"
        code = main(
            [
                "audit",
                str(TEMPLATES / f"{name}.toml"),
                "--step-deg",
                "2",
                "--html",
                str(page),
                "--json",
                str(doc),
                "--quiet",
            ]
        )
        assert code in (0, 1)
        out[name] = (page, json.loads(doc.read_text()))
    return out


@pytest.mark.parametrize("name", CASES)
def test_page_is_self_contained_with_its_figures_and_tables(pages, name):
    page, doc = pages[name]
    text = page.read_text(encoding="utf-8")
    # nothing fetched when viewed: no external script, stylesheet, image or frame in the page's markup (the inlined
    # plotly.js has a link to plotly.com for its logo, which the page switches off: a link, not a fetch)
    markup = re.sub(r"<script[^>]*>.*?</script>", "", text, flags=re.S)
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", markup), "an external reference"
    assert not re.search(r"""<script[^>]*\bsrc\s*=""", text), "a script loaded from elsewhere"
    assert "Plotly" in text[:6_000_000] and text.count("<script") >= 5  # plotly.js inlined once, one script per figure
    for div in ("drive", "tightest", "profile", "vs_angle"):
        assert f'id="{div}"' in text, div
    assert f"{doc['min_clearance_um']:.3f} um" in text  # the table says what the JSON says
    assert ("INTERFERENCE" in text) == doc["interference"]


@pytest.mark.skipif(
    shutil.which("chromium") is None, reason="Debian's chromium not installed (apt-get install chromium)"
)
@pytest.mark.parametrize("name", CASES)
def test_page_loads_in_a_browser_without_console_messages(pages, name):
    page, doc = pages[name]
    res = subprocess.run(
        [
            "chromium",
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=15000",
            "--dump-dom",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=180,
    )
    console = [line for line in res.stderr.splitlines() if "CONSOLE" in line]
    assert not console, console[:3]
    # plotly drew every figure: each leaves an svg of class main-svg in the page's live DOM
    for div in ("drive", "tightest", "profile", "vs_angle"):
        block = res.stdout.split(f'id="{div}"', 1)[1][:20000]
        assert "main-svg" in block, div


def test_html_refused_where_it_cannot_be_written(capsys, tmp_path):
    d4 = str(TEMPLATES / "d4_discrete.toml")
    assert main(["audit", d4, "--html", "-"]) == 2
    assert main(["audit", d4, "--torque-nm", "100", "--html", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert err.count("--html") >= 2 and "Traceback" not in err
    assert not (tmp_path / "x.html").exists()
