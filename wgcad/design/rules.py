"""Declared rules of design keys: unit, bounds (absolute or relative to the design's own sizes), choices, and their check.

Every key of a design table is declared with :func:`key`, which stores its
unit, bounds, allowed choices, a one-line meaning and why the bounds are
what they are in the dataclass field's metadata. :func:`check_bounds` checks
every declared bound of every table of a design, and
:mod:`wgcad.design.reference` writes the reference table of all keys from
the same metadata (``docs/design-keys.md``), so rules and documentation
cannot drift apart. A new table (``[material]``, ``[load]``...) gets both by
declaring its fields with :func:`key`.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Callable
from dataclasses import MISSING, dataclass, field, fields

from ..errors import DesignError

__all__ = ["Rel", "key", "key_meta", "check_bounds", "show", "context", "WHEN_BUILT"]

#: the rule suffix of a key checked by build_drive (it needs the tooth geometry), not when the file is read
WHEN_BUILT = " (checked when the gears are built)"


@dataclass(frozen=True, slots=True)
class Rel:
    """A bound relative to the design's own sizes: ``text`` for people, ``fn(ctx)`` for the check (mm)."""

    text: str
    fn: Callable[[dict], float]

    def __call__(self, ctx: dict) -> float:
        return float(self.fn(ctx))


def key(
    doc: str,
    *,
    unit: str = "",
    lo=None,
    hi=None,
    lo_open: bool = False,
    hi_open: bool = False,
    choices: tuple | None = None,
    rule: str = "",
    why: str = "",
    default=MISSING,
    default_doc: str | None = None,
    inf_ok: bool = False,
):
    """A dataclass field of a design table with its documented rule.

    Parameters
    ----------
    doc : str
        What the key means, one line.
    unit : str
        ``mm``, ``deg``, ``teeth`` or ``""`` (dimensionless).
    lo, hi : float or Rel or None
        Bounds (inclusive unless ``lo_open``/``hi_open``); :class:`Rel` for
        bounds relative to the design (module, pitch diameter...).
    choices : tuple of str, optional
        Allowed values of a string key (checked by :func:`check_bounds`).
    rule : str
        Any further rule checked elsewhere (documentation only).
    why : str
        Why the bounds are what they are.
    default_doc : str, optional
        How the default reads in the reference when it is not a plain value.
    inf_ok : bool
        ``inf`` is a meaningful value (a support stiffness: held), not refused as non-finite.
    """
    meta = {
        "doc": doc,
        "unit": unit,
        "lo": lo,
        "hi": hi,
        "lo_open": lo_open,
        "hi_open": hi_open,
        "choices": choices,
        "rule": rule,
        "why": why,
        "default_doc": default_doc,
        "inf_ok": inf_ok,
    }
    return field(default=default, metadata={"wgcad": meta})


def key_meta(f) -> dict:
    """The rule metadata of a dataclass field (empty dict for an undeclared one)."""
    return f.metadata.get("wgcad", {})


_repr = reprlib.Repr()
_repr.maxlevel, _repr.maxstring, _repr.maxother, _repr.maxlist = 2, 40, 40, 4


def show(value) -> str:
    """A short, safe ``repr`` for error messages (deeply nested or huge values are abbreviated)."""
    try:
        return _repr.repr(value)
    except (RecursionError, ValueError):  # pragma: no cover - reprlib already limits depth
        return f"<{type(value).__name__}>"


def _fmt(x: float) -> str:
    return f"{x:g}"


def bound_text(meta: dict) -> str:
    """The bounds of a key as an interval, e.g. ``(0, 20] mm`` or ``[0.1 m, d]``."""
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is None and hi is None:
        return ""
    a = "-inf" if lo is None else (lo.text if isinstance(lo, Rel) else _fmt(lo))
    b = "inf" if hi is None else (hi.text if isinstance(hi, Rel) else _fmt(hi))
    left = "(" if (lo is None or meta.get("lo_open")) else "["
    right = ")" if (hi is None or meta.get("hi_open")) else "]"
    unit = meta.get("unit", "")
    return f"{left}{a}, {b}{right}" + (f" {unit}" if unit and unit != "teeth" else "")


def context(design) -> dict:
    """The sizes relative bounds refer to (mm): module ``m``, pitch diameters ``d_flex``/``d_rigid``, ``cone_length``."""
    dr = design.drive
    m = dr.module
    return {
        "m": m,
        "d_flex": m * dr.z_flex,
        "d_rigid": m * dr.z_rigid,
        "r_flex": 0.5 * m * dr.z_flex,
        "face_width": dr.face_width,
        "cone_length": design.generator.cone_length,
    }


def _table_ctx(ctx: dict, table: str) -> dict:
    # a gear table's own pitch diameter and radius: d, r
    if table in ("flexspline", "rigid"):
        d = ctx["d_flex"] if table == "flexspline" else ctx["d_rigid"]
        return {**ctx, "d": d, "r": 0.5 * d}
    return ctx


def _check_one(where: str, meta: dict, value, ctx: dict | None) -> None:
    """Check the absolute sides of the bounds (``ctx`` None) or the relative ones (``ctx`` given)."""
    choices = meta.get("choices")
    if choices is not None:
        if ctx is None and value not in choices:
            raise DesignError(where, f"must be one of {', '.join(choices)}; got {show(value)}")
        return
    sides = []
    for b in (meta.get("lo"), meta.get("hi")):
        if b is None or isinstance(b, Rel) != (ctx is not None):
            sides.append(None)  # no bound, or checked in the other pass
        else:
            sides.append(b(ctx) if isinstance(b, Rel) else float(b))
    lo_v, hi_v = sides
    bad_lo = lo_v is not None and (value <= lo_v if meta.get("lo_open") else value < lo_v)
    bad_hi = hi_v is not None and (value >= hi_v if meta.get("hi_open") else value > hi_v)
    if not (bad_lo or bad_hi):
        return
    unit = meta.get("unit", "")
    u = f" {unit}" if unit and unit != "teeth" else ""
    shown = []
    for b, v in ((meta.get("lo"), lo_v), (meta.get("hi"), hi_v)):
        if b is None:
            shown.append(None)
        elif isinstance(b, Rel):
            shown.append(b.text if v is None else f"{b.text} = {_fmt(v)}")
        else:
            shown.append(_fmt(b))
    left = "(" if (shown[0] is None or meta.get("lo_open")) else "["
    right = ")" if (shown[1] is None or meta.get("hi_open")) else "]"
    interval = f"{left}{shown[0] or '-inf'}, {shown[1] or 'inf'}{right}{u}"
    # the why of every bound is in the key reference, which the message points to
    raise DesignError(where, f"must be in {interval}, got {_fmt(value)}{u} (bounds and why: docs/design-keys.md)")


def check_bounds(design, tables: dict, passes: tuple = (0, 1)) -> None:
    """Check every declared bound and choice of every table of ``design``.

    Pass 0 checks the absolute bounds and choices of all tables, pass 1 the
    relative ones (which use the module and tooth counts, so they are only
    evaluated on sane sizes).

    Raises
    ------
    DesignError
        Names ``table.key``, the interval (with the sizes it is relative to)
        and why the bound exists.
    """
    for pass_ in passes:
        ctx = None if pass_ == 0 else context(design)
        for name in tables:
            part = getattr(design, name, None)
            if part is None:
                continue
            tctx = None if ctx is None else _table_ctx(ctx, name)
            for f in fields(part):
                meta = key_meta(f)
                value = getattr(part, f.name)
                if not meta or value is None or isinstance(value, bool):
                    continue
                if isinstance(value, str) and meta.get("choices") is None:
                    continue
                if meta.get("inf_ok") and value == math.inf:
                    continue  # inf is a value of its own here (a held support), beyond the finite bounds
                if isinstance(value, float) and not math.isfinite(value):
                    raise DesignError(f"{name}.{f.name}", f"must be finite, got {_fmt(value)}")
                _check_one(f"{name}.{f.name}", meta, value, tctx)
