"""``[tooth]``, ``[flexspline]`` and ``[rigid]``: the keys of the teeth (docs/design-keys.md; rules in
:func:`wgcad.design.schema.validate`, derived-geometry rules when the gears are built)."""

from __future__ import annotations

from dataclasses import dataclass

from .rules import WHEN_BUILT, Rel
from .rules import key as _key

__all__ = ["ToothFormSpec", "GearSpec"]


@dataclass(frozen=True, slots=True)
class ToothFormSpec:
    """``[tooth]``: tooth form shared by both gears (docs/models.md 2)."""

    form: str = _key(
        "tooth form (double_arc: convex arc, common tangent, concave arc, docs/models.md 2.4)",
        choices=("involute", "cycloidal", "double_arc"),
        default="involute",
    )
    pressure_angle_deg: float = _key(
        "pressure angle alpha (involute)",
        unit="deg",
        lo=5.0,
        hi=45.0,
        default=20.0,
        why="standard 20 deg; harmonic drives use 20-30 deg; below 5 deg the base circle "
        "is the pitch circle, above 45 deg the teeth are pointed",
    )
    addendum_coef: float = _key(
        "addendum coefficient h_a*",
        lo=0.1,
        hi=2.0,
        default=1.0,
        why="harmonic drives use short teeth (0.5-1); above 2 the teeth are pointed for any shift",
    )
    clearance_coef: float | None = _key(
        "root clearance coefficient c*",
        lo=0.0,
        hi=1.0,
        default=None,
        default_doc="0.25 involute and double_arc, 0.1 cycloidal",
        why="usual 0.1-0.4; more than a module of root clearance only thins the rim",
    )
    convex_radius_coef: float | None = _key(
        "double_arc: radius of the convex (addendum) arc rho_a / m",
        lo=0.1,
        hi=10.0,
        default=None,
        default_doc="1.0 (double_arc)",
        rule="only with form = double_arc; it must reach the tip circle" + WHEN_BUILT,
        why="below 0.1 m the arc is sharper than the tooth is deep; beyond 10 m it is a straight flank",
    )
    concave_radius_coef: float | None = _key(
        "double_arc: radius of the concave (dedendum) arc rho_f / m",
        lo=0.1,
        hi=10.0,
        default=None,
        default_doc="1.2 (double_arc)",
        rule="only with form = double_arc; it must reach the root circle with the space open" + WHEN_BUILT,
        why="as convex_radius_coef",
    )
    tangent_angle_deg: float | None = _key(
        "double_arc: inclination of the common tangent against the tooth's radial centre line",
        unit="deg",
        lo=0.0,
        hi=45.0,
        default=None,
        default_doc="20 (double_arc)",
        rule="only with form = double_arc",
        why="the straight part's pressure angle, as an involute's: above 45 deg the teeth are pointed",
    )
    tangent_length_coef: float | None = _key(
        "double_arc: length of the common tangent / m, centred on the datum circle r + x m",
        lo=0.0,
        hi=2.0,
        default=None,
        default_doc="0.2 (double_arc)",
        rule="only with form = double_arc; inside the tip circle" + WHEN_BUILT,
        why="0: the arcs meet at the datum; beyond 2 m the tangent is longer than any tooth is deep",
    )


@dataclass(frozen=True, slots=True)
class GearSpec:
    """``[flexspline]`` / ``[rigid]``: one gear's teeth and body."""

    rim_thickness: float = _key(
        "flexspline: rim under the teeth h1; rigid: wall beyond the root circle",
        unit="mm",
        lo=Rel("0.1 m", lambda c: 0.1 * c["m"]),
        hi=Rel("d", lambda c: c["d"]),
        rule="> 0",
        why="flexspline rims are 0.5-2 m thick, rigid walls several m; thinner than 0.1 m "
        "is foil, thicker than the gear's pitch diameter d no longer a ring",
    )
    shift: float = _key(
        "profile shift coefficient x (involute; 0 for cycloidal)",
        lo=-5.0,
        hi=10.0,
        default=0.0,
        rule="involute: no undercut, tip thickness >= 0.2 m" + WHEN_BUILT,
        why="harmonic drives use x up to about 4 (D1: 3.1/3.2); beyond these limits the teeth are "
        "pointed or the space closed anyway",
    )
    tip_radius: float | None = _key(
        "tip radius, overrides the standard tip",
        unit="mm",
        lo=Rel("r - 15 m", lambda c: c["r"] - 15 * c["m"]),
        hi=Rel("r + 15 m", lambda c: c["r"] + 15 * c["m"]),
        default=None,
        default_doc="standard (docs/models.md 2.1, 2.2)",
        rule="> 0; external teeth: outside the root; internal: inside" + WHEN_BUILT,
        why="the band the shift, addendum and clearance bounds allow around the pitch radius r",
    )
    root_radius: float | None = _key(
        "root radius, overrides the standard root",
        unit="mm",
        lo=Rel("r - 15 m", lambda c: c["r"] - 15 * c["m"]),
        hi=Rel("r + 15 m", lambda c: c["r"] + 15 * c["m"]),
        default=None,
        default_doc="standard (docs/models.md 2.1, 2.2)",
        rule="> 0" + WHEN_BUILT,
        why="as tip_radius",
    )
    thinning: float = _key(
        "tooth-thickness allowance at the pitch circle (backlash)",
        unit="mm",
        default=0.0,
        rule="|thinning| < half the pitch, pi m / 2",
        why="a thinning of half the pitch removes the tooth",
    )
    fillet_coef: float = _key(
        "root fillet radius / m (involute)",
        lo=0.0,
        hi=2.0,
        default=0.25,
        rule="the fillet must fit the root space" + WHEN_BUILT,
        why="usual 0.25-0.38; the largest fillet that fits is searched in [0, 2]",
    )
    measure_diameter: float | None = _key(
        "diameter at which the report gives the tooth thickness (arc and chordal)",
        unit="mm",
        lo=Rel("d - 30 m", lambda c: c["d"] - 30 * c["m"]),
        hi=Rel("d + 30 m", lambda c: c["d"] + 30 * c["m"]),
        default=None,
        default_doc="none (mid-depth only)",
        rule="on the flanks (checked when the report is made)",
        why="as tip_radius, on the diameter",
    )
    pin_diameter: float | None = _key(
        "pin (ball) diameter of the dimension over / between pins",
        unit="mm",
        lo=Rel("0.1 m", lambda c: 0.1 * c["m"]),
        hi=Rel("5 m", lambda c: 5.0 * c["m"]),
        default=None,
        default_doc="chosen: contact nearest mid-flank, pin standing out",
        rule="touches both flanks (checked when the report is made)",
        why="measuring pins are about 1.5-1.9 m; a pin outside [0.1 m, 5 m] cannot touch both flanks",
    )
    flanks: str = _key(
        "the flanks: of [tooth] form, or conjugate to the flexspline's teeth under the law (rigid gear only)",
        choices=("form", "conjugate"),
        default="form",
        rule="conjugate: rigid gear of an internal-deformation drive only (docs/models.md 13)",
    )
    conjugate_z: float | None = _key(
        "axial section whose law the conjugate flanks are made for",
        unit="mm",
        lo=Rel("0", lambda c: 0.0),
        hi=Rel("face width", lambda c: c["face_width"]),
        default=None,
        default_doc="the generator's centre line (generator_z) on a coned cup, else mid-face",
        rule="only with flanks = conjugate",
        why="a section of the toothed rim",
    )
    conjugate_clearance_um: float = _key(
        "normal clearance of conjugate flanks from the flexspline tooth's envelope (designed backlash)",
        unit="um",
        lo=0.0,
        hi=100.0,
        default=0.0,
        rule="only with flanks = conjugate (docs/models.md 13.3)",
        why="a conjugate pair touches without play at its section; a few um absorb the mismatch a coned cup "
        "leaves at the face ends, 100 um is a coarse drive's whole backlash",
    )
    face_modification: str = _key(
        "the flexspline's teeth along the face width: unmodified; offset along their centre lines so that the "
        "depth of engagement stays that of the reference section under coning ('depth'); or offset by "
        "face_taper_um_per_mm ('linear')",
        choices=("none", "depth", "linear"),
        default="none",
        rule="flexspline of a coned cup (generator.cone_length) with internal deformation only; the offset is "
        "0 at the reference section: rigid.conjugate_z with conjugate flanks, else generator.generator_z "
        "(docs/models.md 13.4)",
    )
    face_taper_um_per_mm: float | None = _key(
        "radial offset of the flexspline's teeth per mm along the face from the reference section "
        "(+: outward toward the diaphragm)",
        unit="um/mm",
        lo=-100.0,
        hi=100.0,
        default=None,
        default_doc="none",
        rule="only with face_modification = 'linear'",
        why="coning tilts the rim by W0 / (l - z_h), a few um per mm on cups of the usual proportions; "
        "100 um/mm offsets a 30 mm face by 3 mm, beyond any tooth",
    )
