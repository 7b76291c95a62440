"""Shared fixtures: paths of the bundled templates and a runner for the CLI."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES = ROOT / "templates"


def d1_with_parts(tmp_path, parts: str) -> Path:
    """A copy of D1 in ``tmp_path`` with a ``[parts]`` table of ``parts`` (TOML lines) appended."""
    p = tmp_path / "d1_parts.toml"
    p.write_text((TEMPLATES / "d1_involute.toml").read_text() + "\n[parts]\n" + parts + "\n")
    return p


@pytest.fixture
def template_text():
    def read(name: str) -> str:
        return (TEMPLATES / f"{name}.toml").read_text()

    return read


def edit_toml(text: str, table: str, key: str, value: str | None) -> str:
    """Set (or with value None, remove) ``key`` in ``[table]`` of a TOML text."""
    lines = text.splitlines()
    out, in_table, done = [], False, False
    for line in lines:
        m = re.match(r"\s*\[(\w+)\]", line)
        if m:
            if in_table and not done and value is not None:
                out.append(f"{key} = {value}")
                done = True
            in_table = m.group(1) == table
        elif in_table and re.match(rf"\s*{key}\s*=", line):
            done = True
            if value is not None:
                out.append(f"{key} = {value}")
            continue
        out.append(line)
    if in_table and not done and value is not None:
        out.append(f"{key} = {value}")
    return "\n".join(out) + "\n"
