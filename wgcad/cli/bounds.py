"""The bounds of every numeric flag, in one table: each flag is judged once, while the line is parsed, by one rule.

A flag that sets a library setting takes that setting's bound (:data:`wgcad.audit.BOUNDS`), so the CLI and the
library refuse a value in the same words, not in two ranges of their own. Where one flag means a different quantity in one command, that command's own
row says so (``sector --step-deg`` steps half a turn of sweeps holding every angle at once).
"""

from __future__ import annotations

import argparse
import math

from ..numbers import Bound
from ..services.audit import BOUNDS as AUDIT_BOUNDS

__all__ = ["FLAG_BOUNDS", "COMMAND_BOUNDS", "REVERSE", "bound_of", "bounded"]

#: why a negative torque is refused (audit, ke, sector): the models take the output torque on the working flanks
REVERSE = (
    "the elastic model loads the working flanks only (a reverse torque is not modelled; for a drive symmetric in "
    "its flanks it is the mirror image of the same magnitude)"
)

#: flag -> its bound, in every command that has the flag
FLAG_BOUNDS = {
    "--step-deg": AUDIT_BOUNDS["step_deg"],
    "--sections": AUDIT_BOUNDS["sections"],
    "--chord-tol-um": AUDIT_BOUNDS["chord_tol_um"],
    "--interference-tol-um": AUDIT_BOUNDS["interference_tol_um"],
    "--max-memory-mb": Bound(0.0, 1e7, "MB", lo_open=True),
    "--omega-h": Bound(0.0, 1e6, "rad/s", lo_open=True),
    "--eccentricity": Bound(0.0, 100.0, "mm", lo_open=True),
    "--speed-rpm": Bound(0.0, 1e5, "rpm", lo_open=True),
    # 0: in this process, without Dask (the same rule in sweep and design)
    "--workers": Bound(0, 4096, "worker processes (0: in this process, without Dask)", whole=True),
}

#: (command, flag) -> its bound where the flag means another quantity in that command
COMMAND_BOUNDS = {
    ("sector", "--step-deg"): Bound(0.0, 5.0, "deg", lo_open=True),  # its sweeps hold every angle of half a turn
    ("sector", "--torque-nm"): Bound(0.0, 1e7, "N m", lo_open=True),
    ("sector", "--tip-clearance-um"): Bound(0.0, 999.0, "um"),
    ("rating", "--sections"): Bound(1, 9, "sections", whole=True),  # the elastic model's sections, not the audit's
}


def bound_of(command: str, flag: str) -> Bound:
    """The bound of ``flag`` in ``command``."""
    return COMMAND_BOUNDS.get((command, flag)) or FLAG_BOUNDS[flag]


def bounded(command: str, flag: str):
    """The argparse type of ``flag`` in ``command``: a number within :func:`bound_of`, refused in its one rule."""
    bound = bound_of(command, flag)

    def conv(text: str):
        try:
            val = float(text)
            if bound.whole:
                val = int(text)
        except ValueError:
            kind = "a whole number" if bound.whole else "a number"
            raise argparse.ArgumentTypeError(f"'{text}' is not {kind}") from None
        if not bound.holds(val):
            shown = f"{val:g}" if math.isfinite(val) else str(val)
            why = f": {REVERSE}" if flag == "--torque-nm" and val < 0 else ""
            raise argparse.ArgumentTypeError(f"must be {bound.rule()}, got {shown}{why}")
        return val

    return conv
