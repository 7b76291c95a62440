"""Small text helpers of the printed summaries."""

from __future__ import annotations

__all__ = ["fixed"]


def fixed(x: float, nd: int, width: int = 0) -> str:
    """``x`` with ``nd`` decimals, right-aligned in ``width``; a value that rounds to zero prints as ``0.000``, never
    ``-0.000`` (once: the no-load row of a load table read -0.0000 arcmin of wind-up)."""
    r = round(float(x), nd)
    if r == 0.0:
        r = 0.0  # drops the sign of -0.0
    return f"{r:{width}.{nd}f}"
