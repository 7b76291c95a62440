"""The figures a sweep can record for each sample: what each means, which model computes it, which design tables it sees.

Three models, each run once per sample for all its figures:

* ``ke`` (:mod:`wgcad.accuracy.ke`, docs/models.md 6.2): no-load kinematic
  error and lost motion of the imperfect drive over one flexspline
  revolution; sees the geometry and ``[imperfections]``;
* ``audit`` (:mod:`wgcad.clearance.engine`, docs/models.md 5): the no-load
  clearance audit of the perfect drive; sees the geometry only;
* ``load`` (:mod:`wgcad.elastic`, docs/models.md 4.1): the
  elastic contact model at the torques named in the figure
  (``entry_gap_um@500Nm``); sees the geometry, ``[material]``,
  ``[bearing]`` and ``[load]`` (its cam offset), not ``[imperfections]``.
"""

from __future__ import annotations

import re

from ..errors import DesignError, close_matches

__all__ = ["FIGURES", "LOADED", "MODELS", "parse_figure", "check_figures", "figure_doc"]

_GEOM = ("drive", "tooth", "flexspline", "rigid", "generator")
#: design tables each model sees (a parameter no recorded figure sees is refused: it would change nothing)
MODELS = {
    "ke": _GEOM + ("imperfections",),
    "audit": _GEOM,
    "load": _GEOM + ("material", "bearing", "load"),
}
#: no-load figures: name -> (model, meaning)
FIGURES = {
    "ke_pp_arcsec": ("ke", "largest kinematic error (peak to peak over one flexspline revolution), no load"),
    "lost_motion_min_arcsec": ("ke", "smallest lost motion over the revolution (negative: the teeth interfere)"),
    "lost_motion_max_arcsec": ("ke", "largest lost motion over the revolution"),
    "ke_deep_overlap_fraction": (
        "ke",
        "share of the angles whose first contact overlaps so deeply (turns back > 300 "
        "arcsec to separate) that the linear error model is not to be trusted there",
    ),
    "min_clearance_um": ("audit", "smallest clearance of the perfect drive, no load (negative: interference)"),
    "entry_gap_um": ("audit", "entry gap of the perfect drive, no load"),
    "backlash_arcmin": ("audit", "backlash of the perfect drive (NaN where the teeth touch or interfere)"),
}
#: figures under load, recorded as ``NAME@TNm`` (T the output torque in N m)
LOADED = {
    "entry_gap_um": "entry gap under load (smallest over waves and sections)",
    "teeth_in_contact": "teeth carrying load",
    "min_clearance_um": "smallest clearance of the unloaded pairs",
    "wind_up_arcmin": "torsional wind-up of the output",
    "largest_tooth_force_n": "largest force on one tooth",
    "max_ball_load_n": "largest load on one rolling body of the flexible bearing",
}
_AT = re.compile(r"^([a-z_]+)@([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)Nm$")


def parse_figure(name: str) -> tuple[str, str, float | None]:
    """``(model, base name, torque N m or None)`` of a recorded figure name.

    Raises
    ------
    DesignError
        Unknown figure (the message lists the valid ones).
    """
    m = _AT.match(name)
    if m:
        base, t = m.group(1), float(m.group(2))
        if base not in LOADED:
            near = close_matches(base, LOADED)
            raise DesignError(
                "figures.record",
                f"'{name}': no loaded figure '{base}'"
                + (f"; did you mean '{near[0]}@{m.group(2)}Nm'?" if near else f"; loaded figures: {', '.join(LOADED)}"),
            )
        if not 0.0 <= t <= 1e7:
            raise DesignError("figures.record", f"'{name}': torque must be in [0, 1e7] N m")
        return "load", base, t
    if "@" in name:
        raise DesignError("figures.record", f"'{name}': a loaded figure reads NAME@TORQUENm, e.g. entry_gap_um@500Nm")
    if name not in FIGURES:
        near = close_matches(name, list(FIGURES) + [f"{k}@500Nm" for k in LOADED])
        raise DesignError(
            "figures.record",
            f"unknown figure '{name}'"
            + (
                f"; did you mean '{near[0]}'?"
                if near
                else f"; figures: {', '.join(FIGURES)}, and NAME@TNm for {', '.join(LOADED)}"
            ),
        )
    return FIGURES[name][0], name, None


def figure_doc(name: str) -> str:
    model, base, t = parse_figure(name)
    return f"{LOADED[base]} at {t:g} N m" if t is not None else FIGURES[base][1]


def check_figures(spec, base_design) -> None:
    """Refuse what cannot be computed: a figure the base design's model cannot give, a parameter no figure sees."""
    canon = [(b if t is None else f"{b}@{t:g}Nm") for _, b, t in map(parse_figure, spec.record)]
    if len(set(canon)) != len(canon):
        raise DesignError("figures.record", "a figure is named twice (the same torque written two ways)")
    models = {parse_figure(r)[0] for r in spec.record}
    if "ke" in models and base_design.drive.fixed != "rigid":
        raise DesignError(
            "figures.record",
            "the KE figures model a fixed rigid gear (docs/models.md 6.2); the base design has drive.fixed = flexspline",
        )
    if "load" in models and base_design.bearing.balls is None:
        raise DesignError(
            "figures.record",
            "figures under load need the elastic model's [bearing] table in the base design (bearing.balls is missing)",
        )
    for p in spec.parameters:
        if p.table == "sectors":
            raise DesignError(f"parameters.{p.name}", "no sweep figure models the sectored rigid gear")
        seen = [m for m in models if p.table in MODELS[m]]
        if not seen:
            who = ", ".join(sorted(m for m in MODELS if p.table in MODELS[m])) or "none"
            raise DesignError(
                f"parameters.{p.name}",
                f"no recorded figure depends on [{p.table}] (models that see it: {who}); "
                "record a figure of one of them or drop the parameter",
            )
