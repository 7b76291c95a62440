"""The package as a user installs it: one version, the extras and their one-line errors, the bundled templates, and
the sdist and wheel (built with ``python -m build``, checked by twine, the wheel run in a fresh environment away
from the checkout)."""

import os
import re
import subprocess
import sys
import sysconfig
import tomllib
import zipfile
from pathlib import Path

import pytest
from conftest import ROOT, TEMPLATES

import wgcad
from wgcad.cli import main
from wgcad.errors import DependencyError
from wgcad.extras import EXTRAS, message, require

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def test_the_version_is_written_once():
    """pyproject.toml reads the version from wgcad.__version__, ``wgcad --version`` prints it, and the changelog's
    newest entry is that version."""
    project = PYPROJECT["project"]
    assert "version" not in project and "version" in project["dynamic"]
    assert PYPROJECT["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "wgcad.__version__"}
    res = subprocess.run([sys.executable, "-m", "wgcad", "--version"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and res.stdout == f"wgcad {wgcad.__version__}\n"
    heads = re.findall(r"^## (\S+)", (ROOT / "CHANGELOG.md").read_text(), flags=re.M)
    assert heads and heads[0] == wgcad.__version__


def test_the_extras_agree_with_pyproject():
    """Every extra wgcad/extras.py names is declared in pyproject.toml with the distribution its message names,
    [all] brings every one, and [test] brings [all] (the tests run every command)."""
    extras = PYPROJECT["project"]["optional-dependencies"]
    for name, (_, dist, _) in EXTRAS.items():
        assert name in extras, name
        assert any(req.replace("[", ".").startswith(dist) for req in extras[name]), (name, extras[name])
    (everything,) = extras["all"]
    assert set(re.fullmatch(r"wgcad\[(.+)\]", everything).group(1).split(",")) == set(EXTRAS) | {"parquet"}
    assert "wgcad[all,docs]" in extras["test"]
    core = " ".join(PYPROJECT["project"]["dependencies"])
    for dist in ("dask", "optuna", "plotly", "matplotlib", "build123d"):
        assert dist not in core, f"{dist} serves one command: an extra, not a core dependency"


def _tpl(name):
    return str(TEMPLATES / f"{name}.toml")


#: (command line, module made missing, the extra its message must name); the check comes before any work
MISSING = [
    (["generate", _tpl("d4_discrete"), "--generator-angle", "0"], "matplotlib", "plots"),
    (["audit", _tpl("d4_discrete"), "--plot", "{tmp}/a"], "matplotlib", "plots"),
    (["audit", _tpl("d4_discrete"), "--html", "{tmp}/a.html"], "plotly", "html"),
    (["audit", _tpl("d1_involute"), "--torque-nm", "100", "--html", "{tmp}/a.html"], "plotly", "html"),
    (["ke", _tpl("d2_imperfect"), "--plot", "{tmp}/k"], "matplotlib", "plots"),
    (["ke", _tpl("d2_imperfect"), "--html", "{tmp}/k.html"], "plotly", "html"),
    (["rating", _tpl("d1_involute"), "--plot", "{tmp}/r.png"], "matplotlib", "plots"),
    (["rating", _tpl("d1_involute"), "--html", "{tmp}/r.html"], "plotly", "html"),
    (["kinematics", _tpl("d3_external"), "--out", "{tmp}/o"], "matplotlib", "plots"),
    (["sector", _tpl("d4_sectored"), "--out", "{tmp}/o"], "matplotlib", "plots"),
    (["sweep", str(TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml"), "--out", "{tmp}/o"], "distributed", "sweep"),
    (["sweep", str(TEMPLATES / "sweeps" / "d2_tolerance_sweep.toml"), "--out", "{tmp}/o"], "matplotlib", "plots"),
    (["design", str(TEMPLATES / "requirements" / "d1_ratio100.toml"), "--out", "{tmp}/o"], "optuna", "design"),
    (
        ["design", str(TEMPLATES / "requirements" / "d1_ratio100.toml"), "--out", "{tmp}/o", "--workers", "2"],
        "distributed",
        "sweep",
    ),
]


@pytest.mark.parametrize("argv, module, extra", MISSING, ids=[f"{a[0]}-{m}" for a, m, _ in MISSING])
def test_a_command_without_its_extra_names_it_in_one_line(argv, module, extra, tmp_path, monkeypatch, capsys):
    """The package made unimportable (``sys.modules[name] = None``, what Python does for a blocked import): exit 5,
    one line naming the extra to install, nothing written."""
    monkeypatch.setitem(sys.modules, module, None)
    code = main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    err = capsys.readouterr().err
    assert code == 5, err
    assert err.count("\n") == 1 and err.startswith("wgcad: error: ") and f"pip install 'wgcad[{extra}]'" in err, err
    assert list(tmp_path.iterdir()) == []


def test_with_the_extra_installed_the_same_check_passes(monkeypatch):
    """The counterpart: with every package present nothing is refused (the test above is not always red)."""
    require(*EXTRAS)
    monkeypatch.setitem(sys.modules, "plotly", None)
    with pytest.raises(DependencyError, match=re.escape(message("html", "--html"))):
        require("plots", "html", what="--html")


def test_the_library_edges_name_the_extra_too(monkeypatch):
    """A library caller gets the same one line, not a bare ModuleNotFoundError: a picture without matplotlib, a page
    without plotly."""
    from wgcad.export.pages.rating import rating_html
    from wgcad.export.pictures.mpl import pyplot

    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(DependencyError, match=r"pip install 'wgcad\[plots\]'"):
        pyplot()
    monkeypatch.setitem(sys.modules, "plotly", None)
    with pytest.raises(DependencyError, match=r"pip install 'wgcad\[html\]'"):
        rating_html(None)


def test_wgcad_templates_lists_and_copies_every_bundled_file(tmp_path, capsys):
    """Every TOML file under templates/ is listed with its kind and title and copied byte for byte, sub-folders kept;
    a second copy refuses to replace a file (exit 2) and writes nothing."""
    files = sorted(p.relative_to(TEMPLATES).with_suffix("").as_posix() for p in TEMPLATES.rglob("*.toml"))
    assert main(["templates"]) == 0
    listing = capsys.readouterr().out
    listed = [line.split()[0] for line in listing.splitlines()[1:]]
    assert sorted(listed) == files
    assert "d1_involute  " in listing and "D1 involute (S1)" in listing
    assert main(["templates", "--copy", str(tmp_path / "t"), "--quiet"]) == 0
    for name in files:
        assert (tmp_path / "t" / f"{name}.toml").read_bytes() == (TEMPLATES / f"{name}.toml").read_bytes()
    (tmp_path / "t" / "d2.toml").unlink()
    assert main(["templates", "--copy", str(tmp_path / "t"), "--quiet"]) == 2
    assert not (tmp_path / "t" / "d2.toml").exists()
    assert "never replaces" in capsys.readouterr().err


def test_a_copied_requirements_file_brings_its_base_design(tmp_path, capsys):
    """``--copy DIR requirements/d1_ratio100`` copies the design its ``base`` names too, so the copy runs as is; a
    misspelt name is refused with the right one suggested."""
    assert main(["templates", "--copy", str(tmp_path), "requirements/d1_ratio100", "--quiet"]) == 0
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.toml")) == [
        "d1_involute.toml",
        "requirements/d1_ratio100.toml",
    ]
    assert main(["templates", "--copy", str(tmp_path / "x"), "d1_invlute"]) == 2
    assert "did you mean 'd1_involute'" in capsys.readouterr().err


def _clean_env():
    """This process's environment without PYTHONPATH (which points at the checkout) and without a virtual
    environment's variables: what the fresh environment's wgcad command sees."""
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}


@pytest.fixture(scope="module")
def dist(tmp_path_factory):
    """The sdist and the wheel ``python -m build`` makes of the checkout (the wheel built from the sdist, so a file
    missing from the sdist is missing from the wheel too)."""
    out = tmp_path_factory.mktemp("dist")
    res = subprocess.run(
        [sys.executable, "-m", "build", "--outdir", str(out), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=900,
        env=_clean_env(),
    )
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    (sdist,) = out.glob(f"wgcad-{wgcad.__version__}.tar.gz")
    (wheel,) = out.glob(f"wgcad-{wgcad.__version__}-py3-none-any.whl")
    return sdist, wheel


def test_twine_check_passes(dist):
    res = subprocess.run(
        [sys.executable, "-m", "twine", "check", "--strict", *map(str, dist)], capture_output=True, text=True
    )
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stdout.count("PASSED") == 2


def test_the_wheel_holds_the_package_and_its_templates(dist):
    """Every module of the checkout's package and every bundled template (byte for byte), and the metadata's
    extras; nothing of the tests."""
    _, wheel = dist
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        for p in TEMPLATES.rglob("*.toml"):
            arc = "wgcad/templates/" + p.relative_to(TEMPLATES).as_posix()
            assert arc in names, arc
            assert z.read(arc) == p.read_bytes()
        meta = z.read(f"wgcad-{wgcad.__version__}.dist-info/METADATA").decode()
    modules = {p.relative_to(ROOT).as_posix() for p in (ROOT / "wgcad").rglob("*.py") if "templates" not in p.parts}
    assert modules <= names, sorted(modules - names)[:5]
    assert not any(n.startswith("tests/") for n in names)
    assert f"Version: {wgcad.__version__}" in meta
    for extra in (*EXTRAS, "all", "test"):
        assert f"Provides-Extra: {extra}" in meta


def test_the_wheel_runs_in_a_fresh_environment(dist, tmp_path):
    """The wheel installed (no dependencies fetched) into a new virtual environment whose only other packages are
    this one's (a .pth file: no network), run from a folder outside the checkout without PYTHONPATH: wgcad is
    imported from the new environment, not the checkout, and ``wgcad templates --copy`` then ``wgcad generate``
    on the copied template writes the drawing."""
    _, wheel = dist
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=300)
    py = venv / "bin" / "python"
    res = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(py), "install", "-q", "--no-deps", "--no-index", str(wheel)],
        capture_output=True,
        text=True,
        timeout=600,
        env=_clean_env(),
    )
    assert res.returncode == 0, res.stdout + res.stderr
    site = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    (Path(site) / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    work = tmp_path / "work"
    work.mkdir()

    def run(*argv):
        r = subprocess.run(argv, cwd=work, capture_output=True, text=True, timeout=600, env=_clean_env())
        assert r.returncode == 0, r.stdout + r.stderr
        return r.stdout

    where = run(str(py), "-c", "import wgcad; print(wgcad.__file__)")
    assert Path(where.strip()).is_relative_to(venv), where
    wgcad_cmd = str(venv / "bin" / "wgcad")
    assert run(wgcad_cmd, "--version") == f"wgcad {wgcad.__version__}\n"
    assert "d1_involute" in run(wgcad_cmd, "templates")
    run(wgcad_cmd, "templates", "--copy", "mine", "d4_discrete", "--quiet")
    run(wgcad_cmd, "generate", "mine/d4_discrete.toml", "--out", "out", "--no-stl", "--quiet")
    assert (work / "out" / "d4_discrete.dxf").stat().st_size > 10_000
    assert (work / "out" / "d4_discrete.report.json").is_file()
