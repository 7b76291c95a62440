"""Small plane-geometry helpers shared by the profiles, the placement and the exporters (numpy only)."""

from __future__ import annotations

import numpy as np

__all__ = ["signed_area"]


def signed_area(pts) -> float:
    """Signed area (mm^2) of the closed polygon ``(N, 2)`` (closing edge implicit): positive counter-clockwise (shoelace)."""
    p = np.asarray(pts, dtype=float)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
