"""Timing helper shared by the benchmark scripts."""

import time

__all__ = ["best_of"]


def best_of(fn, n=3):
    """Fastest of ``n`` runs of ``fn()`` and that run's result, as ``(seconds, result)``."""
    best = (float("inf"), None)
    for _ in range(n):
        t = time.perf_counter()
        val = fn()
        best = min(best, (time.perf_counter() - t, val), key=lambda x: x[0])
    return best
