"""The text of wgcad's JSON documents: indented, NaN refused (a figure that is not a number is ``null`` or absent
before it gets here)."""

from __future__ import annotations

import json

__all__ = ["json_text"]


def json_text(doc, **kw) -> str:
    """``doc`` as indented JSON text (``kw``: more of ``json.dumps``'s options), no trailing newline."""
    return json.dumps(doc, allow_nan=False, indent=2, **kw)
