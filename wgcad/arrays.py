"""Small numpy helpers for the hot paths (numpy only)."""

from __future__ import annotations

import numpy as np

__all__ = ["unique_sorted", "median"]


def unique_sorted(a) -> np.ndarray:
    """The sorted distinct values of a plain numeric array without NaN, as ``np.unique(a)``.

    ``np.unique`` imports ``numpy.ma`` on its first call to ask whether the
    array is masked: 6 ms of every audit's start, more than most of its
    steps (benchmarks/startup.py).
    """
    s = np.sort(np.asarray(a).ravel())
    if s.size < 2:
        return s
    keep = np.empty(s.size, dtype=bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]


def median(a) -> float:
    """The median of a plain numeric array without NaN, as ``np.median(a)`` (which imports ``numpy.ma``)."""
    s = np.sort(np.asarray(a, dtype=float).ravel())
    n = s.size
    if n == 0:
        return float("nan")
    return float(s[n // 2]) if n % 2 else float((s[n // 2 - 1] + s[n // 2]) / 2.0)
