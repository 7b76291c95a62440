"""Closed outlines made ready for export: duplicate and closing vertices removed (numpy only)."""

from __future__ import annotations

import math

import numpy as np

from wgcad.constants import DUPLICATE_TOL

__all__ = ["clean_outline"]


def clean_outline(outline, tol: float = DUPLICATE_TOL, what: str = "outline", too_few: type = ValueError) -> np.ndarray:
    """Remove consecutive duplicate vertices and a repeated closing vertex.

    Parameters
    ----------
    outline : (N, 2) float array_like
        Closed polygon, closing edge implicit or explicit.
    tol : float
        Vertices closer than this (mm) to the previous kept vertex are dropped.
    what : str
        Name used in error messages.
    too_few : exception class
        Raised when fewer than 3 distinct vertices remain.

    Returns
    -------
    (M, 2) float64 ndarray
        ``M <= N``; the last vertex differs from the first.

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
    if len(pts) > 1:
        step = np.hypot(*np.diff(pts, axis=0).T)
        pts = pts[np.concatenate(([True], step > tol))]
    while len(pts) > 1 and math.hypot(*(pts[-1] - pts[0])) <= tol:
        pts = pts[:-1]
    if len(pts) < 3:
        raise too_few(f"{what} has {len(pts)} distinct vertices, needs at least 3")
    return pts
