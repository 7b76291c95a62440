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

CASES = ["d4_discrete", "d2_imperfect"]


def _browse(page):
    """The page's live DOM after headless chromium ran its scripts, asserting it logged no console message."""
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
    return res  # a perfect drive, and one with errors (every passage's entry gap)


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
    res = _browse(page)
    # plotly drew every figure: each leaves an svg of class main-svg in the page's live DOM
    for div in ("drive", "tightest", "profile", "vs_angle"):
        block = res.stdout.split(f'id="{div}"', 1)[1][:20000]
        assert "main-svg" in block, div


def test_html_refused_where_it_cannot_be_written(capsys, tmp_path):
    d4 = str(TEMPLATES / "d4_discrete.toml")
    assert main(["audit", d4, "--html", "-"]) == 2
    # a design the load audit refuses (no [bearing]) writes no page
    assert main(["audit", d4, "--torque-nm", "100", "--html", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert err.count("--html") >= 1 and "Traceback" not in err
    assert not (tmp_path / "x.html").exists()


# ---------------------------------------------------------------- the other commands' pages (issue 23)
def _spec(tmp_path):
    """D1's design study (a 3 x 2 grid of loaded drives) as it ships, with its design path made absolute."""
    text = (TEMPLATES / "sweeps" / "d1_design_study.toml").read_text()
    text = text.replace('design = "../d1_involute.toml"', f'design = "{(TEMPLATES / "d1_involute.toml").as_posix()}"')
    p = tmp_path / "study.toml"
    p.write_text(text)
    return p


OTHER = {
    "rating": (lambda d, tmp: ["rating", str(TEMPLATES / "d2.toml")], ("wind_up", "stress", "criteria")),
    "load": (
        lambda d, tmp: ["audit", str(TEMPLATES / "d1_involute.toml"), "--torque-nm", "0:1000:500", "--quiet"],
        ("entry_gap", "forces", "wind_up"),
    ),
    "ke": (lambda d, tmp: ["ke", str(TEMPLATES / "d2_imperfect.toml"), "--per-mesh", "4"], ("ke", "spectrum")),
    "sweep": (
        lambda d, tmp: ["sweep", str(_spec(tmp)), "--workers", "0", "--out", str(tmp / "w"), "--no-plots", "--quiet"],
        ("surface",),
    ),
}


@pytest.fixture(scope="module")
def other_pages(tmp_path_factory):
    out = {}
    for cmd, (args, divs) in OTHER.items():
        tmp = tmp_path_factory.mktemp(cmd)
        page = tmp / f"{cmd}.html"
        code = main([*args(None, tmp), "--html", str(page)])
        assert code in (0, 1), cmd
        out[cmd] = page
    return out


@pytest.mark.parametrize("cmd", list(OTHER))
def test_every_command_page_is_self_contained(other_pages, cmd):
    text = other_pages[cmd].read_text(encoding="utf-8")
    markup = re.sub(r"<script[^>]*>.*?</script>", "", text, flags=re.S)
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", markup), "an external reference"
    assert not re.search(r"""<script[^>]*\bsrc\s*=""", text), "a script loaded from elsewhere"
    for div in OTHER[cmd][1]:
        assert f'id="{div}"' in text, div
    assert "<table>" in text


def test_the_rating_page_says_what_the_datasheet_says(other_pages, tmp_path):
    text = other_pages["rating"].read_text(encoding="utf-8")
    out = tmp_path / "r.json"
    main(["rating", str(TEMPLATES / "d2.toml"), "--json", str(out)])
    doc = json.loads(out.read_text())
    assert f"rated torque {doc['rated_torque_nm']:.0f} N m" in text and doc["binding_criterion"] in text


@pytest.mark.skipif(
    shutil.which("chromium") is None, reason="Debian's chromium not installed (apt-get install chromium)"
)
@pytest.mark.parametrize("cmd", list(OTHER))
def test_every_command_page_loads_in_a_browser(other_pages, cmd):
    res = _browse(other_pages[cmd])
    for div in OTHER[cmd][1]:
        block = res.stdout.split(f'id="{div}"', 1)[1][:20000]
        assert "main-svg" in block, div


@pytest.mark.parametrize("cmd", ["rating", "ke"])
def test_html_to_standard_output_is_refused(cmd, capsys):
    design = TEMPLATES / ("d2.toml" if cmd == "rating" else "d2_imperfect.toml")
    assert main([cmd, str(design), "--html", "-"]) == 2
    err = capsys.readouterr().err
    assert "--html" in err and "Traceback" not in err


def test_the_ke_curve_is_thinned_to_its_extremes():
    """161600 KE angles (D2) drawn as at most 20000 points: every block's least and greatest value kept, so the peak
    to peak read off the page is the computed one."""
    import numpy as np

    from wgcad.export.pages.ke import MAX_POINTS, _envelope

    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 100.0, 161600)
    y = np.sin(x * 7.0) * 40 + rng.normal(0, 5, x.size)
    tx, ty, b = _envelope(x, y)
    assert len(ty) <= MAX_POINTS + b and b > 1
    assert ty.max() == y.max() and ty.min() == y.min()
    assert np.all(np.diff(tx) > 0)
    sx, sy, b1 = _envelope(x[:500], y[:500])
    assert b1 == 1 and len(sy) == 500
