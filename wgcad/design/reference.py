"""The reference of every design key (table, key, unit, default, rule and bounds, why), written from the schema itself.

``python -m wgcad.design.reference > docs/design-keys.md`` regenerates the
document; ``tests/test_design_reference.py`` fails when it differs from the
schema, so the reference cannot drift from the rules that are checked.
"""

from __future__ import annotations

import sys
import typing
from dataclasses import MISSING, fields

from .files import MAX_DESIGN_BYTES
from .parts import MAX_BOLTS, MAX_PART_MM, PARTS_DOC, PartsSpec, part_sizes
from .rules import bound_text, key_meta
from .schema import OPTIONAL_TABLES, TABLES

__all__ = ["design_keys_markdown"]

_HEAD = """# Design keys

Every key of a wgcad design file (TOML, one table per part), with its unit,
default, rule and bounds, and why the bounds are what they are. Written from
the schema (`wgcad/design/`) by `python -m wgcad.design.reference`; a test
fails when this file and the schema differ.

- Lengths in mm, angles in degrees where the key says `_deg`; `m` is the
  module, `d` the pitch diameter `m z` of the gear the table describes,
  `d_flex` and `r_flex` those of the flexspline.
- A key without a default is required. Unknown keys and tables are errors
  (with the nearest valid name suggested).
- Bounds are checked when the file is read, absolute ones first, then those
  relative to the design's sizes; rules marked *(checked when the gears are
  built)* need the tooth geometry and are checked by `build_drive`.
- A violated rule stops the run with one line naming `table.key` and the
  rule, exit code 2, nothing written.
- Design files must be regular files of at most {max_bytes} bytes (a FIFO, a
  device or a directory is refused without being read).
- Before a run allocates anything large, its memory is estimated from these
  keys and the run settings (`wgcad/design/budget.py`) and the run is refused
  when the estimate exceeds `--max-memory-mb` (default 2048).
"""


def _type_name(tp) -> str:
    if isinstance(tp, str):
        return tp.replace(" | None", " or none")
    args = typing.get_args(tp)
    if args:
        return " or ".join("none" if a is type(None) else a.__name__ for a in args)
    return tp.__name__


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _default(f, meta) -> str:
    if meta.get("default_doc"):
        return meta["default_doc"]
    if f.default is MISSING:
        return "required"
    if isinstance(f.default, str):
        return f'"{f.default}"'
    return repr(f.default)


def design_keys_markdown() -> str:
    """The key reference as Markdown, one section per table, one row per key."""
    out = [_HEAD.format(max_bytes=MAX_DESIGN_BYTES)]
    seen: dict[type, str] = {}
    for table, cls in TABLES.items():
        opt = " (optional table)" if table in OPTIONAL_TABLES else ""
        out.append(f"\n## [{table}]{opt}\n")
        if cls in seen:
            out.append(f"Same keys as [{seen[cls]}]" + (", for the rigid gear.\n" if table == "rigid" else ".\n"))
            continue
        seen[cls] = table
        doc = (cls.__doc__ or "").strip().splitlines()[0]
        out.append(doc.split(": ", 1)[-1] + "\n")
        out.append("| key | type | unit | default | bounds | rule | meaning | why the bounds |")
        out.append("|---|---|---|---|---|---|---|---|")
        for f in fields(cls):
            meta = key_meta(f)
            choices = meta.get("choices")
            bounds = bound_text(meta) if not choices else "one of " + ", ".join(f'"{c}"' for c in choices)
            row = [
                f"`{f.name}`",
                _type_name(f.type),
                meta.get("unit", ""),
                _default(f, meta),
                bounds,
                meta.get("rule", ""),
                meta.get("doc", ""),
                meta.get("why", ""),
            ]
            out.append("| " + " | ".join(_cell(c) for c in row) + " |")
    out.append(_parts_section())
    return "\n".join(out) + "\n"


def _parts_section() -> str:
    """``[parts]`` (read by ``wgcad parts`` only): every key optional, derived from the gear size when absent."""
    lines = [
        "\n## [parts] (optional table, read by `wgcad parts`)\n",
        "Sizes of the flexspline cup, the wave-generator plug and the rigid gear's body. Every key is optional; "
        "an absent key is derived from the gear size (rules below the table); the derived sizes are then checked "
        "to fit together (bolt circles within their annuli, holes not overlapping, a diaphragm within the cup, "
        "a bearing that fits the plug).\n",
        "| key | type | unit | default | bounds | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for f in fields(PartsSpec):
        count = f.name.endswith("_count")
        bounds = f"1 <= value <= {MAX_BOLTS}" if count else f"0 < value <= {MAX_PART_MM:g}"
        row = [f"`{f.name}`", "int" if count else "float", "" if count else "mm", "derived", bounds, PARTS_DOC[f.name]]
        lines.append("| " + " | ".join(_cell(c) for c in row) + " |")
    doc = " ".join(ln.strip() for ln in (part_sizes.__doc__ or "").split("Raises")[0].splitlines()[1:] if ln.strip())
    lines.append("\n" + doc + "\n")
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    sys.stdout.write(design_keys_markdown())
