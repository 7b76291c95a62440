"""From polygon candidates to the exact minimum: the refinement cascade both 2D audits use (docs/models.md 5).

The polygon search leaves every sample whose polygon figure is within the
polygon-curve margin of the polygon minimum. Many of them (a flat minimum)
are first measured again on polygons ``fine`` times finer, whose margin is
as much smaller; then the lowest few are refined on the exact curves to set
a bar, and every candidate whose polygon figure less the polygon-curve gap
is still below the bar is refined in one more call (a refinement's cost is
per call more than per sample). A candidate whose polygon figure less the
gap is not below the best exact figure cannot hold the minimum.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["refine_candidates", "FINE", "FINE_ABOVE"]

#: above this many candidates they are first sorted out on polygons FINE times finer (chord tolerance / 8:
#: margin 8 times smaller), which costs one finer outline and a polygon pass, far less than refining
#: hundreds of samples on the curves
FINE_ABOVE = 48
FINE = 8
#: candidates refined first to set the bar (the lowest polygon figures)
FIRST = 16


def refine_candidates(
    values: np.ndarray,
    gap: float,
    exact: Callable[[np.ndarray], np.ndarray],
    fine: Callable[[np.ndarray], tuple[np.ndarray, float]] | None = None,
    one_call: int = 0,
    progress: Callable[[float], None] | None = None,
) -> tuple[float, int, int, int]:
    """The smallest exact figure among candidates, and which candidate holds it.

    Parameters
    ----------
    values : (N,) float
        The candidates' polygon figures (mm), any order; N >= 1.
    gap : float
        Largest difference between a polygon figure and the exact one (mm).
    exact : callable
        ``exact(idx)``: the exact figures of candidates ``idx`` (indices into ``values``).
    fine : callable, optional
        ``fine(idx, bar)``: ``(figures on finer polygons, their gap)``, used
        when there are more than :data:`FINE_ABOVE` candidates; ``bar`` is the
        best exact figure so far (a pair that cannot go below it need not be
        measured: its figure may read inf).
    one_call : int
        Up to this many candidates are refined in a single call (no bar first).
    progress : callable, optional
        ``progress(fraction)`` of the candidates passed.

    Returns
    -------
    best : float
        The smallest exact figure.
    where : int
        Index into ``values`` of the candidate holding it.
    n_refined, n_fine : int
        Candidates measured on the exact curves and on the finer polygons.
    """
    order = np.argsort(values, kind="stable")
    v = np.asarray(values, dtype=float)[order]
    n_fine = 0
    best, where = np.inf, int(order[0])
    n_refined = 0
    if fine is not None and len(v) > FINE_ABOVE:
        # the lowest few on the exact curves first: their best is a bar no candidate whose polygon figure less
        # the gap is above can beat, which leaves fewer for the finer polygons
        first = np.asarray(exact(order[:FIRST]), dtype=float)
        n_refined = len(first)
        j = int(np.argmin(first))
        best, where = float(first[j]), int(order[j])
        rest = np.nonzero(v[FIRST:] - gap < best)[0] + FIRST
        if progress is not None:
            progress(0.1)
        if rest.size == 0:
            return best, where, n_refined, n_fine
        order, v = order[rest], v[rest]
        if len(v) > FINE_ABOVE:
            v, gap = fine(order, best)
            n_fine = len(v)
            o = np.argsort(v, kind="stable")
            order, v = order[o], v[o]
            keep = v <= v[0] + 2.0 * gap
            order, v = order[keep], v[keep]
    at = 0 if not n_refined else -1
    if at < 0:  # the bar is set: every candidate that can still beat it, in one call
        at = 0
        if not len(v) or v[0] - gap >= best:
            return best, where, n_refined, n_fine
        live = np.nonzero(v - gap < best)[0]
        vals = np.asarray(exact(order[live]), dtype=float)
        n_refined += len(vals)
        j = int(np.argmin(vals))
        if vals[j] < best:
            best, where = float(vals[j]), int(order[live[j]])
        if progress is not None:
            progress(1.0)
        return best, where, n_refined, n_fine
    while at < len(v):
        # candidates are in increasing order: once one cannot beat the best exact figure, none after it can
        if v[at] - gap >= best:
            break
        if at:
            live = np.nonzero(v[at:] - gap < best)[0] + at
        else:
            live = np.arange(len(v) if len(v) <= one_call else min(FIRST, len(v)))
        if live.size == 0:
            break
        vals = np.asarray(exact(order[live]), dtype=float)
        n_refined += len(vals)
        j = int(np.argmin(vals))
        if vals[j] < best:
            best, where = float(vals[j]), int(order[live[j]])
        at = int(live[-1]) + 1 if at == 0 else len(v)
        if progress is not None:
            progress(at / len(v))
    return best, where, n_refined, n_fine
