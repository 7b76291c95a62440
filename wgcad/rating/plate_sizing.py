"""The cup's diaphragm sized for fatigue: the part set's and the datasheet's one diaphragm (docs/models.md 10.1).

Where ``[parts]`` leaves the diaphragm's thickness (and the cup's bolt
circle) to be derived, they are chosen so that the plate of
:mod:`wgcad.rating.diaphragm` meets Goodman's safety ``[load]
fatigue_safety_min`` at ``[load] rated_torque_nm`` (the torque the bolts are
sized for): the bolt circle as far out as the annulus allows (the outer limit
moving inward by 0.5 mm, the bolts chosen for the torque again at each step,
:func:`wgcad.design.bolting.choose_bolts`), at each circle the thickest plate
from the derived default down to half the cup wall (0.05 mm steps) that meets
the criterion. Sizes ``[parts]`` gives are kept and checked: one that fails
gets a warning naming the part. Both ``wgcad parts`` and ``wgcad rating``
call :func:`sized_parts`, so the datasheet rates the cup the part set exports.
"""

from __future__ import annotations

import math
from dataclasses import replace

from wgcad.design.bolting import choose_bolts
from wgcad.design.parts import PartsSpec, part_sizes
from wgcad.errors import DesignError

from .diaphragm import H_STEP, R_STEP, Diaphragm, PlateCheck, plate_safety
from .fatigue import strength

__all__ = ["sized_parts", "cup_wall_thickness", "plate_of"]

_CUP_BOLTS = ("cup_bolt_circle_diameter", "cup_bolt_count", "cup_bolt_hole_diameter")


def cup_wall_thickness(drive) -> float:
    """The cup wall the models and the rating use, mm: ``[material] cup_wall_thickness_mm`` or the rim's."""
    d = drive.design
    return float(d.material.cup_wall_thickness_mm or d.flexspline.rim_thickness)


def plate_of(drive, values: dict) -> Diaphragm:
    """The plate of the sizes ``values``: clamped at the cup's bolt circle, joined to the wall's mid-surface."""
    d = drive.design
    r_o = drive.flex_rim_radius + 0.5 * cup_wall_thickness(drive)
    arm = d.generator.cone_length - d.generator.generator_z
    return Diaphragm(0.5 * values["cup_bolt_circle_diameter"], r_o, values["diaphragm_thickness"], arm)


def _sizable(drive) -> bool:
    """A cup (internal deformation, coned) with the strengths the criterion needs."""
    d = drive.design
    outside = drive.flex.r_f > drive.flex_rim_radius
    return not drive.external and drive.coned and outside and d.material.ultimate_strength_mpa is not None


def _check(drive, values, st) -> PlateCheck:
    d = drive.design
    m = d.material
    T = d.load.rated_torque_nm or 0.0
    return plate_safety(drive.law, plate_of(drive, values), m.youngs_modulus_gpa * 1e3, m.poisson, T, st)


def _thickest(drive, values, st, h_hi, h_lo, need) -> tuple[float | None, PlateCheck]:
    """The thickest plate on the 0.05 mm grid in ``[h_lo, h_hi]`` meeting ``need``, and the best check seen."""
    best = None
    k = 0
    while True:
        h = round(h_hi - k * H_STEP, 6)
        if h < h_lo - 1e-9:
            return None, best
        c = _check(drive, {**values, "diaphragm_thickness": h}, st)
        if best is None or c.safety > best.safety:
            best = c
        if c.safety >= need:
            return h, c
        k += 1


def _search(drive, v, bolts_free: bool, h_free: bool, st, need):
    """The sizes meeting ``need``: ``(values, check, met, bolt rule)``; unmet: the best sizes seen."""
    d = drive.design
    r_in = drive.flex_rim_radius
    r_hub = 0.5 * v["hub_bore_diameter"]
    h_hi = v["diaphragm_thickness"]
    h_lo = max(H_STEP, 0.5 * cup_wall_thickness(drive)) if h_free else h_hi
    T = d.load.rated_torque_nm
    best = None
    r_hi = r_in
    text = None
    while True:
        trial = dict(v)
        if bolts_free and r_hi < r_in:
            try:
                c = choose_bolts(T, r_hub, r_hi, "cup") if T else None
            except DesignError:
                break  # no bolt circle further in carries the torque
            if c is not None:
                text = c.text(T)
                trial.update(
                    cup_bolt_circle_diameter=round(math.floor(2.0 * c.radius_mm / 0.05 + 1e-9) * 0.05, 6),
                    cup_bolt_count=c.count,
                    cup_bolt_hole_diameter=c.hole_mm,
                )
            else:  # no torque: the geometric rule's holes, on a circle a hole inside the limit
                hole = trial["cup_bolt_hole_diameter"]
                if r_hi - hole - 0.5 * hole < r_hub + 0.5 * hole:
                    break
                trial["cup_bolt_circle_diameter"] = round(2.0 * (r_hi - hole), 6)
        h, chk = _thickest(drive, trial, st, h_hi, h_lo, need)
        if best is None or chk.safety > best[1].safety:
            best = ({**trial, "diaphragm_thickness": chk.plate.h}, chk, text)
        if h is not None:
            return {**trial, "diaphragm_thickness": h}, chk, True, text
        if not bolts_free:
            break
        r_hi -= R_STEP
    return best[0], best[1], False, best[2]


def sized_parts(spec: PartsSpec, drive):
    """:func:`wgcad.design.parts.part_sizes` with the diaphragm sized for fatigue (module docstring).

    Returns the :class:`~wgcad.design.parts.PartSizes` with the sized keys,
    each with its rule, and a warning naming the diaphragm when the sizes
    given, or the best admissible ones, fall short of the criterion.
    """
    sizes = part_sizes(spec, drive)
    if not _sizable(drive):
        return sizes
    d = drive.design
    st = strength(d.material, d.flexspline.rim_thickness, d.drive.face_width)
    need = d.load.fatigue_safety_min
    T = d.load.rated_torque_nm or 0.0
    h_free = spec.diaphragm_thickness is None
    bolts_free = all(getattr(spec, k) is None for k in _CUP_BOLTS)
    v = dict(sizes.values)
    if h_free or bolts_free:
        # the bolt circle inward at the derived thickness first (the plate's tilting stiffness kept), thinner only
        # where no circle carries the torque with it
        v0 = v
        v, chk, met, text = _search(drive, v0, bolts_free, False, st, need)
        if not met and h_free:
            v, chk, met, text = _search(drive, v0, bolts_free, True, st, need)
    else:
        chk = _check(drive, v, st)
        met, text = chk.safety >= need, None
    rules, notes = dict(sizes.rules), list(sizes.notes)
    rule = (
        f"sized for fatigue: Goodman safety {chk.safety:.2f} (hub {chk.hub:.2f}, wall {chk.wall:.2f}) at "
        f"{T:g} N m, [load] fatigue_safety_min {need:g}"
    )
    if h_free:
        rules["diaphragm_thickness"] = rule
    if bolts_free and v["cup_bolt_circle_diameter"] != sizes.values["cup_bolt_circle_diameter"]:
        c = text or f"{v['cup_bolt_count']} holes of {v['cup_bolt_hole_diameter']:g} mm"
        for k in _CUP_BOLTS:
            rules[k] = f"{c}; the circle moved in until the diaphragm is {rule}"
    wall = cup_wall_thickness(drive)
    if abs(v["shell_thickness"] - wall) > 1e-9:
        notes.append(
            f"cup wall: [parts] shell_thickness {v['shell_thickness']:g} mm is not the {wall:g} mm wall the elastic "
            "model and the rating take ([material] cup_wall_thickness_mm): the datasheet rates that wall, not the "
            "cup exported"
        )
    if not met:
        given = [k for k in ("diaphragm_thickness", *_CUP_BOLTS) if getattr(spec, k) is not None]
        how = f"[parts] {', '.join(given)} as given" if given else "no admissible size"
        notes.append(
            f"diaphragm ({v['diaphragm_thickness']:g} mm thick, clamped at the {v['cup_bolt_circle_diameter']:g} mm "
            f"bolt circle): Goodman safety {chk.safety:.2f} at {T:g} N m, below [load] fatigue_safety_min {need:g} "
            f"({how}; docs/models.md 10.1)"
        )
    return replace(sizes, values=v, rules=rules, notes=tuple(notes))
