"""matplotlib at the edge: pyplot on the Agg backend, imported only when a picture is drawn, and figures rendered to PNG bytes."""

from __future__ import annotations

import io

from ...extras import require

__all__ = ["pyplot", "png_bytes"]


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed); without matplotlib, the extra to install (exit 5)."""
    require("plots")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def png_bytes(fig, tight_layout: bool = False, **savefig) -> bytes:
    """Render ``fig`` to PNG bytes (``savefig`` options passed on) and release it."""
    plt = pyplot()
    if tight_layout:
        fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", **savefig)
    plt.close(fig)
    return buf.getvalue()
