"""Closed outlines made ready for export: near-duplicate and closing vertices removed down to the file formats' precision (numpy only)."""

from __future__ import annotations

import math

import numpy as np

from wgcad.constants import DUPLICATE_TOL

__all__ = ["clean_outline", "min_spacing", "FLOAT32_ULPS"]

#: Smallest allowed distance between neighbouring exported vertices, in
#: float32 units in the last place (ulp) of the outline's largest coordinate.
#: STL stores float32: two vertices closer than ``sqrt(2)`` ulp can round to
#: the same point, and a reader that merges them gets a mesh that is no
#: longer watertight (once: the d1_cycloidal rigid gear had two root
#: vertices 0.06 nm apart). 4 ulp leaves every neighbour at least two distinct
#: float32 values apart in one coordinate. At 100 mm this is 4 x 7.6e-6 =
#: 3.1e-5 mm, 1/30 of the 1 um chord tolerance: dropping such a vertex moves
#: the outline by at most that much. The same spacing is used for DXF so
#: both files of a gear hold the same vertices.
FLOAT32_ULPS = 4


def min_spacing(points) -> float:
    """Smallest neighbour distance kept in an exported outline, mm.

    ``max(DUPLICATE_TOL, FLOAT32_ULPS * ulp32(max |coordinate|))``.

    Parameters
    ----------
    points : (N, 2) float array_like

    Returns
    -------
    float
    """
    big = float(np.max(np.abs(points))) if np.size(points) else 0.0
    return max(DUPLICATE_TOL, FLOAT32_ULPS * float(np.spacing(np.float32(big))))


def clean_outline(outline, tol: float | None = None, what: str = "outline", too_few: type = ValueError) -> np.ndarray:
    """Remove near-duplicate vertices and a repeated closing vertex.

    Walks the outline and keeps a vertex only when it lies more than ``tol``
    from the last *kept* vertex (so a run of tiny steps cannot silently
    delete a long stretch, and no gap between kept neighbours is ``<= tol``).

    Parameters
    ----------
    outline : (N, 2) float array_like
        Closed polygon, closing edge implicit or explicit.
    tol : float, optional
        Vertices this close (mm) to the last kept vertex are dropped; default
        :func:`min_spacing` of the outline.
    what : str
        Name used in error messages.
    too_few : exception class
        Raised when fewer than 3 distinct vertices remain.

    Returns
    -------
    (M, 2) float64 ndarray
        ``M <= N``; every pair of neighbours, the closing pair included, is
        more than ``tol`` apart.

    Raises
    ------
    ValueError
        If the input is not (N, 2) finite.

    Examples
    --------
    >>> clean_outline([[0, 0], [1, 0], [1, 0], [0, 1], [0, 0]]).tolist()
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    """
    pts = np.asarray(outline, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"{what} must be an (N, 2) array, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise ValueError(f"{what} has non-finite coordinates")
    if tol is None:
        tol = min_spacing(pts)
    if len(pts) > 1:
        step = np.hypot(*np.diff(pts, axis=0).T)
        if np.any(step <= tol):
            # rare (a few clusters): greedy walk against the last kept vertex
            keep = np.zeros(len(pts), dtype=bool)
            keep[0] = True
            lx, ly = pts[0]
            for i in range(1, len(pts)):
                x, y = pts[i]
                if math.hypot(x - lx, y - ly) > tol:
                    keep[i] = True
                    lx, ly = x, y
            pts = pts[keep]
    while len(pts) > 1 and math.hypot(*(pts[-1] - pts[0])) <= tol:
        pts = pts[:-1]
    if len(pts) < 3:
        raise too_few(f"{what} has {len(pts)} distinct vertices, needs at least 3")
    return pts
