"""The bundled templates: the design, requirements and sweep files shipped inside the package (``wgcad/templates``,
the checkout's ``templates/`` folder), found with :mod:`importlib.resources` so a wheel installed without the
checkout has them too (``wgcad templates`` lists them and copies them out)."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .atomic import atomic_batch, check_target, check_writable_dir
from .errors import DesignError, OutputError, close_matches

__all__ = ["Template", "template_root", "templates", "copy_templates"]


@dataclass(frozen=True, slots=True)
class Template:
    """One bundled file: ``name`` its path under the templates folder without ``.toml`` (``sweeps/d2_tolerance_sweep``),
    ``kind`` design, requirements or sweep, ``title`` the name it gives itself (``[drive] name``, a sweep's
    ``name``), ``path`` where it is on disk."""

    name: str
    kind: str
    title: str
    path: Path


def template_root() -> Path:
    """The folder of the bundled templates inside the installed package."""
    return Path(str(resources.files("wgcad") / "templates"))


def _title(path: Path) -> str:
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    for table in ("drive", "sweep", "requirements"):
        value = doc.get(table, {})
        if isinstance(value, dict) and isinstance(value.get("name"), str):
            return value["name"]
    return doc.get("name", "") if isinstance(doc.get("name"), str) else ""


def templates() -> list[Template]:
    """Every bundled template, designs first, then requirements and sweeps, each by name."""
    root = template_root()
    out = []
    for path in sorted(root.rglob("*.toml")):
        rel = path.relative_to(root).with_suffix("")
        kind = {"requirements": "requirements", "sweeps": "sweep"}.get(rel.parts[0], "design") if rel.parts else ""
        out.append(Template(rel.as_posix(), kind, _title(path), path))
    order = {"design": 0, "requirements": 1, "sweep": 2}
    return sorted(out, key=lambda t: (order[t.kind], t.name))


def copy_templates(dest, names=None) -> list[Path]:
    """Copy the bundled templates (all, or those ``names``) into the folder ``dest``, keeping their sub-folders so a
    requirements file's ``base = "../d1_involute.toml"`` still points at its design; written together atomically,
    an existing file is never replaced (:class:`~wgcad.errors.OutputError` naming it, nothing written).

    Returns the paths written."""
    known = {t.name: t for t in templates()}
    if names:
        chosen = []
        for n in names:
            key = n.removesuffix(".toml")
            if key not in known:
                hint = close_matches(key, known)
                raise DesignError(
                    "templates", f"no bundled template '{n}'" + (f"; did you mean '{hint[0]}'?" if hint else "")
                )
            chosen.append(known[key])
        # a requirements file or a sweep needs the design it names, relative to itself
        for t in list(chosen):
            ref = _design_ref(t)
            if ref in known and known[ref] not in chosen:
                chosen.append(known[ref])
    else:
        chosen = list(known.values())
    dest = check_writable_dir(dest)
    targets = [(t, dest / f"{t.name}.toml") for t in chosen]
    for _, target in targets:
        if target.exists():
            raise OutputError(f"{target}: exists; wgcad templates --copy never replaces a file")
        check_target(target)
    with atomic_batch() as batch:
        for t, target in targets:
            Path(batch.temp_path(target)).write_bytes(t.path.read_bytes())
    return [target for _, target in targets]


def _design_ref(t: Template) -> str | None:
    """The template name of the design a requirements file (``base``) or a sweep (``design``) names, if bundled."""
    doc = tomllib.loads(t.path.read_text(encoding="utf-8"))
    table, key = {"requirements": ("requirements", "base"), "sweep": ("sweep", "design")}.get(t.kind, ("", ""))
    ref = doc.get(table, {}).get(key) if table else None
    if not isinstance(ref, str):
        return None
    parts: list[str] = []
    for p in (Path(t.name).parent / ref).as_posix().removesuffix(".toml").split("/"):
        if p == "..":
            if not parts:
                return None
            parts.pop()
        elif p not in ("", "."):
            parts.append(p)
    return "/".join(parts)
