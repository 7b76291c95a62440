"""The text of wgcad's JSON documents: indented, NaN refused (a figure that is not a number is ``null`` or absent
before it gets here). ``json`` loads on the first document, so a run that writes none never loads it."""

from __future__ import annotations

__all__ = ["json_text"]


def json_text(doc, **kw) -> str:
    """``doc`` as indented JSON text (``kw``: more of ``json.dumps``'s options), no trailing newline."""
    import json

    return json.dumps(doc, allow_nan=False, indent=2, **kw)
