"""The design change that lets a sectored drive that interferes run: the generator's W0 that clears the cycle best, and
the side clearance (flexspline thinning) that clears it at the design's W0 (docs/models.md 2.3).

Both are measured, not estimated: every candidate is the design with one value changed, its tooth heights built by
the design's own rule, swept over the cycle by the sectored audit. W0 moves the two sectors apart: the transmission
sectors want the wave that makes their teeth follow their pitch, the coupling sectors none (docs/models.md 2.3), so
the smallest clearance rises with W0 while a transmission sector limits it and falls once a coupling sector does; the
search brackets that peak on a grid and refines it by golden section. Thinning widens every space: a flank's
clearance grows by ``cos(alpha) / 2`` per unit of thinning, which sizes the step, and the audit checks it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace

__all__ = ["DesignChange", "remedies", "cycle_clearance", "W0_STEP", "SEARCH_STEP_DEG"]

#: ``w0_coef`` step of the scan away from the design's W0: a window of W0 that runs narrower than this can be missed
W0_STEP = 0.05
#: the scan goes no further than these ``w0_coef``: half a module's wave leaves no engagement with tip circles a
#: module apart, and 2.5 m is beyond a two-wave sector layout's transmission wave (2 m for sectors a quarter turn each)
W0_RANGE = (0.5, 2.5)
#: the golden section stops when the bracket is this narrow (w0_coef): W0 to 0.5 % of a module
_W0_TOL = 0.005
#: generator-angle step of the search's sweeps, deg: the smallest clearance of D4 moves by < 0.06 um from 1 to 0.1 deg
#: steps (docs/models.md 2.3); the change found is checked again at the design's step
SEARCH_STEP_DEG = 1.0
_GOLD = 0.5 * (math.sqrt(5.0) - 1.0)


@dataclasses.dataclass(frozen=True)
class DesignChange:
    """One design value changed and what the sectored audit then finds over the cycle (lengths mm).

    ``removes``: no tip-to-tip contact and no flank interference left at ``step_deg``; ``note``: why no value
    was found (``value`` NaN, or the last one tried).
    """

    key: str
    value: float
    was: float
    min_clearance: float
    tip_to_tip_teeth: int
    step_deg: float
    removes: bool
    evaluations: int
    note: str = ""


def _with(design, key: str, value: float):
    table, name = key.split(".")
    return replace(design, **{table: replace(getattr(design, table), **{name: float(value)})})


def cycle_clearance(design, heights_mode: str, assign: str, step_deg: float, tip_clearance_um=None):
    """The sectored audit over the cycle of ``design`` with its tooth heights built by its rule: the audit."""
    from .built import built_gear
    from .scene import SectoredScene, sectored_audit

    g = built_gear(design, heights_mode, assign, step_deg, tip_clearance_um)
    return sectored_audit(SectoredScene(g["drive"], g["layout"], g["teeth"], g["built"]), step_deg)


def _golden(f, a: float, b: float) -> tuple[float, float, int]:
    """The largest ``f`` in ``[a, b]`` by golden section to ``_W0_TOL``: (x, f(x), evaluations)."""
    x1, x2 = b - _GOLD * (b - a), a + _GOLD * (b - a)
    f1, f2 = f(x1), f(x2)
    n = 2
    while b - a > _W0_TOL:
        if f1 >= f2:
            b, x2, f2 = x2, x1, f1
            x1 = b - _GOLD * (b - a)
            f1 = f(x1)
        else:
            a, x1, f1 = x1, x2, f2
            x2 = a + _GOLD * (b - a)
            f2 = f(x2)
        n += 1
    return (x1, f1, n) if f1 >= f2 else (x2, f2, n)


def _search_w0(f, w0: float, down_first: bool, margin: float) -> tuple[float | None, int]:
    """The nearest ``w0_coef`` to ``w0`` at which ``f`` (the smallest clearance) reaches ``margin``: a scan in steps of
    W0_STEP (first down, where a coupling sector limits the design, else up), then the peak of ``f`` within a step of
    the first value that clears. ``(w0_coef or None, evaluations)``."""
    n = 0
    for sign in (-1.0, 1.0) if down_first else (1.0, -1.0):
        k = 1
        while True:
            x = round(w0 + sign * k * W0_STEP, 6)
            if not W0_RANGE[0] <= x <= W0_RANGE[1]:
                break
            n += 1
            if f(x) >= margin:
                xb, fb, m = _golden(f, x - W0_STEP, x + W0_STEP)
                return (xb if fb >= margin else x), n + m
            k += 1
    return None, n


def remedies(
    design,
    heights_mode: str,
    assign: str,
    step_deg: float,
    tip_clearance_um=None,
    audit_result=None,
    margin: float | None = None,
) -> list[DesignChange]:
    """The design changes that remove the interference of a sectored drive (module docstring), each checked at
    ``step_deg``: ``generator.w0_coef`` at the peak of the smallest clearance (None if the peak still interferes, then
    reported as found), and ``flexspline.thinning`` that leaves ``margin`` (default two chord tolerances: what the
    polygons' figure may differ from the curves', docs/models.md 5) at the design's W0.

    ``audit_result``: the design's own sectored audit at ``step_deg``, if at hand (where it is worst chooses the
    direction of the W0 scan, its smallest clearance sizes the thinning).
    """
    from ..constants import CHORD_TOL, INTERFERENCE_TOL
    from ..errors import DesignError

    tol = INTERFERENCE_TOL
    margin = 2.0 * CHORD_TOL if margin is None else margin
    out = []

    def audit(d, step):
        return cycle_clearance(d, heights_mode, assign, step, tip_clearance_um)

    evals = [0]

    def f(x):
        evals[0] += 1
        try:
            return audit(_with(design, "generator.w0_coef", x), SEARCH_STEP_DEG).min_clearance
        except DesignError:  # a wave too shallow for the teeth to meet, or too deep for the rim
            return -math.inf

    w0 = design.generator.w0_coef
    first = audit(design, step_deg) if audit_result is None else audit_result
    c0 = first.min_clearance
    # the transmission sectors want a deeper wave, the coupling sectors a shallower one (module docstring)
    down = first.worst is None or first.worst.sector_kind == "coupling"
    x, n = _search_w0(f, w0, down, margin)
    if x is not None:
        x = round(x, 3)
        a = audit(_with(design, "generator.w0_coef", x), step_deg)
        out.append(
            DesignChange(
                "generator.w0_coef",
                x,
                w0,
                a.min_clearance,
                len(a.tip_to_tip),
                step_deg,
                not a.interferes and a.min_clearance >= -tol,
                n + 1,
            )
        )
    else:
        out.append(DesignChange("generator.w0_coef", float("nan"), w0, float("nan"), -1, step_deg, False, n))
    # the side clearance at the design's W0: cos(alpha)/2 of clearance per unit of thinning on a flank (module docstring)
    t0 = design.flexspline.thinning
    per = 0.5 * math.cos(math.radians(design.tooth.pressure_angle_deg))
    c, t, n, a, note = c0, t0, 0, None, ""
    for _ in range(4):
        t = round(t + max(margin - c, 0.0) / per, 4)
        try:
            a = audit(_with(design, "flexspline.thinning", t), step_deg)
        except DesignError as e:  # the thinning the flanks need leaves no tooth
            a, note = None, str(e)
            break
        n += 1
        c = a.min_clearance
        if c >= margin:
            break
    if a is None:
        out.append(DesignChange("flexspline.thinning", t, t0, float("nan"), -1, step_deg, False, n, note))
    else:
        out.append(
            DesignChange(
                "flexspline.thinning",
                t,
                t0,
                a.min_clearance,
                len(a.tip_to_tip),
                step_deg,
                not a.interferes and a.min_clearance >= -tol,
                n,
            )
        )
    return out
