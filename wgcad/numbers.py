"""Numbers read from files (design, sweep spec, baseline): one bounded parser, a one-line error naming the key."""

from __future__ import annotations

import math

from .errors import DesignError

__all__ = ["MAX_INT", "show_value", "read_float", "read_int"]

#: whole numbers above this are refused before any arithmetic: every key's own bound is far below it, and a
#: float holds every whole number up to it exactly
MAX_INT = 2**53


def show_value(value) -> str:
    """``value`` as an error message shows it: short (a huge integer by its digit count, a long text cut)."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INT:
        return f"a {len(str(abs(value)))}-digit integer"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def read_float(where: str, value) -> float:
    """A finite number (TOML integer or float) as a float; a bool, text, NaN, infinity or an integer too large for
    a float is refused (:class:`~wgcad.errors.DesignError` naming ``where``)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DesignError(where, f"must be a number, got {type(value).__name__} {show_value(value)}")
    if isinstance(value, int) and abs(value) > MAX_INT:
        raise DesignError(where, f"must be a finite number of a sane size, got {show_value(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise DesignError(where, f"must be finite, got {value}")
    return value


def read_int(where: str, value) -> int:
    """A whole number (TOML integer) up to :data:`MAX_INT` in size; anything else refused naming ``where``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise DesignError(where, f"must be a whole number, got {type(value).__name__} {show_value(value)}")
    if abs(value) > MAX_INT:
        raise DesignError(where, f"must be a whole number of a sane size, got {show_value(value)}")
    return value
