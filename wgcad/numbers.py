"""Numbers read from files (design, sweep spec, baseline) and lists of numbers given to flags (torque levels,
generator angles): one bounded parser each, a one-line error naming the key or the flag."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import DesignError

__all__ = ["MAX_INT", "Bound", "show_value", "read_float", "read_int", "read_values"]

#: whole numbers above this are refused before any arithmetic: every key's own bound is far below it, and a
#: float holds every whole number up to it exactly
MAX_INT = 2**53


@dataclass(frozen=True, slots=True)
class Bound:
    """The range of one number a flag or setting takes, and the one rule its refusal states (``lo_open``: ``lo``
    itself excluded; ``whole``: a whole number ``lo..hi``)."""

    lo: float
    hi: float
    unit: str = ""
    lo_open: bool = False
    whole: bool = False

    def rule(self) -> str:
        """``"in (0, 90] deg"`` or ``"1..200 sections"``: the words every refusal of this number uses."""
        if self.whole:
            return f"{self.lo:g}..{self.hi:g} {self.unit}".rstrip()
        return f"in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}] {self.unit}".rstrip()

    def holds(self, value: float) -> bool:
        if not math.isfinite(value) or value > self.hi or (self.whole and value != int(value)):
            return False
        return value > self.lo if self.lo_open else value >= self.lo

    def check(self, where: str, value):
        """``value`` if it holds, else :class:`~wgcad.errors.DesignError` naming ``where`` with :meth:`rule`."""
        if not self.holds(value):
            raise DesignError(where, f"must be {self.rule()}, got {value:g}")
        return value


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


def _rule_range(lo: float, hi: float, unit: str) -> str:
    if hi == math.inf:
        return f">= {lo:g} {unit}"
    if lo == -math.inf:
        return f"<= {hi:g} {unit}"
    return f"in [{lo:g}, {hi:g}] {unit}"


def read_values(
    where: str,
    text: str,
    *,
    what: str,
    unit: str,
    max_count: int,
    lo: float = -math.inf,
    hi: float = math.inf,
) -> list[float]:
    """The numbers of a flag's ``START:STOP:STEP`` (STOP included when the steps reach it), single value or comma
    list: each finite and within ``[lo, hi]`` (``unit``), at most ``max_count`` of them.

    The count is judged from the text before any list is built (``0:1e12:1`` is refused, not built), and infinity
    and NaN are refused as bad input, like any value out of bounds: :class:`~wgcad.errors.DesignError` naming
    ``where`` (the flag) with the rule broken. ``what`` names the values in the messages (e.g. ``"torques"``).
    """
    text = text.strip()
    form = f"expected START:STOP:STEP, a value or a comma list of {what} in {unit}, got {show_value(text)}"

    def number(part: str) -> float:
        try:
            val = float(part)
        except ValueError:
            raise DesignError(where, form) from None
        if not math.isfinite(val):
            raise DesignError(where, f"{what} must be finite numbers, got {part.strip()}")
        return val

    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise DesignError(where, form)
        start, stop, step = (number(x) for x in parts)
        if not step > 0:
            raise DesignError(where, f"START:STOP:STEP needs STEP > 0, got {step:g}")
        if stop < start:
            raise DesignError(where, f"START:STOP:STEP needs STOP >= START, got {start:g}:{stop:g}")
        steps = (stop - start) / step  # may be inf (stop - start above the largest float): refused below
        if not steps + 1 <= max_count:
            count = f"{math.floor(steps + 1e-9) + 1}" if steps < 1e15 else f"{steps:.3g}"
            raise DesignError(
                where,
                f"{show_value(text)} makes {count} {what}, more than the {max_count} one run takes: "
                "a coarser STEP or a narrower range",
            )
        values = [start + i * step for i in range(math.floor(steps + 1e-9) + 1)]
    else:
        parts = text.split(",")
        if len(parts) > max_count:
            raise DesignError(where, f"{len(parts)} {what}, more than the {max_count} one run takes")
        values = [number(x) for x in parts]
    for v in values:
        if not lo <= v <= hi:
            raise DesignError(where, f"{what} must be {_rule_range(lo, hi, unit)}, got {v:g}")
    return values
