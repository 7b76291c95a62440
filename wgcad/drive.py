"""A design turned into geometry: both gears, the neutral line and the deformation law."""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, replace
from math import pi

import numpy as np

from . import constants
from .design import Design
from .design.budget import DEFAULT_MAX_MEMORY_MB, RunShape, check_budget, estimate_run
from .envelope.rigid import conjugate_rigid_gear
from .errors import DesignError
from .laws import Law, coned_w0, make_law
from .profiles.double_arc import DEFAULTS
from .profiles.gear import Gear, ToothSpec, make_gear, tooth_radii

__all__ = ["Drive", "build_drive", "tooth_spec"]


def tooth_spec(design: Design, which: str) -> ToothSpec:
    """The :class:`ToothSpec` of ``which`` (``"flexspline"`` or ``"rigid"``) of a design.

    Internal deformation: external-toothed flexspline, internal rigid gear;
    external deformation the other way round (docs/models.md 1). The flexspline's
    tooth 0 is centred on +x, the rigid gear's space is (reference position).
    """
    d = design
    gs = getattr(d, which)
    flex = which == "flexspline"
    z = d.drive.z_flex if flex else d.drive.z_rigid
    internal = (not flex) if not d.external else flex
    return ToothSpec(
        z=z,
        module=d.drive.module,
        internal=internal,
        form=d.tooth.form,
        alpha=float(np.deg2rad(d.tooth.pressure_angle_deg)),
        addendum_coef=d.tooth.addendum_coef,
        clearance_coef=d.c_star,
        shift=gs.shift,
        tip_radius=gs.tip_radius,
        root_radius=gs.root_radius,
        thinning=gs.thinning,
        fillet_coef=gs.fillet_coef,
        field=which,
        phase=0.0 if flex else pi / z,
        **_double_arc(d),
    )


def _double_arc(d: Design) -> dict:
    """The double-arc parameters of a ToothSpec (docs/models.md 2.4), the form's defaults where the design gives none."""
    if d.tooth.form != "double_arc":
        return {}

    t, m = d.tooth, d.drive.module

    def get(key):
        v = getattr(t, key)
        return DEFAULTS[key] if v is None else v

    return {
        "convex_radius": get("convex_radius_coef") * m,
        "concave_radius": get("concave_radius_coef") * m,
        "tangent_angle": float(np.deg2rad(get("tangent_angle_deg"))),
        "tangent_length": get("tangent_length_coef") * m,
    }


@dataclass(frozen=True, slots=True)
class Drive:
    """Geometry of a whole drive, undeformed, plus its deformation law.

    Attributes
    ----------
    design : Design
    flex, rigid : Gear
    law : Law
        Deformation of the flexspline's neutral line at the generator's
        centre section (``W0`` of the design).
    r_m : float
        Neutral-line radius of the flexspline rim, mm: the middle of the rim
        under the teeth (docs/models.md 1).
    flex_rim_radius, rigid_rim_radius : float
        The other boundary of each gear body, mm (flexspline bore or outer
        surface; rigid gear outer surface or bore).
    """

    design: Design
    flex: Gear
    rigid: Gear
    law: Law
    r_m: float
    flex_rim_radius: float
    rigid_rim_radius: float
    tol: float

    @property
    def external(self) -> bool:
        return self.design.external

    @property
    def coned(self) -> bool:
        return self.design.generator.cone_length is not None

    def law_at(self, z: float) -> Law:
        """The deformation law of the cross-section at axial position ``z`` (mm from the open end), docs/models.md 3.1."""
        g = self.design.generator
        if g.cone_length is None:
            return self.law
        w0 = float(coned_w0(self.law.w0, np.atleast_1d(float(z)), length=g.cone_length, z_h=g.generator_z)[0])
        law = self.law.with_w0(w0)
        off = self.tooth_offset(z)
        return law if off == law.tooth_offset else replace(law, tooth_offset=off)

    @property
    def face_reference_z(self) -> float | None:
        """Axial section (mm) where a face modification is zero: the conjugate section, else the generator's centre line."""
        d = self.design
        if not self.coned:
            return None
        if d.rigid.flanks == "conjugate" and d.rigid.conjugate_z is not None:
            return float(d.rigid.conjugate_z)
        return float(d.generator.generator_z)

    @property
    def face_taper(self) -> float:
        """Radial offset of the flexspline's teeth per mm along the face (mm/mm; docs/models.md 13.4).

        ``depth``: coning changes the amplitude by ``-W0 / (l - z_h)`` per mm, so the teeth move out by as much
        and the depth of engagement on the major axis is the reference section's everywhere.
        """
        fs = self.design.flexspline
        if fs.face_modification == "depth":
            g = self.design.generator
            return float(self.design.w0 / (g.cone_length - g.generator_z))
        if fs.face_modification == "linear":
            return 1e-3 * float(fs.face_taper_um_per_mm)
        return 0.0

    def sampled_at(self, tol: float) -> Drive:
        """This drive with its outlines sampled at chord tolerance ``tol``: the same exact curves (a conjugate rigid
        gear's pieces sampled anew, its flank not enveloped again at that tolerance)."""
        return build_drive(self.design, tol=tol, rigid_gear=self.rigid.sampled_at(tol))

    def with_face_taper(self, taper_um_per_mm: float) -> Drive:
        """This drive with its flexspline's teeth offset linearly along the face (``face_modification = 'linear'``).

        The gears are kept: the offset is zero at the reference section, where a conjugate rigid gear is made.
        """
        fs = replace(self.design.flexspline, face_modification="linear", face_taper_um_per_mm=float(taper_um_per_mm))
        drive = replace(self, design=replace(self.design, flexspline=fs))
        return replace(drive, law=replace(self.law, tooth_offset=drive.tooth_offset(None)))

    def tooth_offset(self, z: float | None) -> float:
        """Offset (mm) of the flexspline's teeth along their centre lines in section ``z`` (None: the centre section)."""
        taper = self.face_taper
        if taper == 0.0:
            return 0.0
        z = self.design.generator.generator_z if z is None else float(z)
        return taper * (z - self.face_reference_z)

    def sections(self, k: int) -> np.ndarray:
        """Axial positions of ``k`` cross-sections spread over the face width (ends included for k >= 2), mm."""
        bw = self.design.drive.face_width
        return np.array([0.5 * bw]) if k <= 1 else np.linspace(0.0, bw, k)


def _check_teeth_meet(design: Design) -> None:
    """Refuse a drive whose teeth never meet: on the major axis the flexspline tips must reach past the rigid tips (docs/models.md 2.1, 3)."""
    f, b = tooth_radii(tooth_spec(design, "flexspline")), tooth_radii(tooth_spec(design, "rigid"))
    w0 = design.w0
    g = design.generator
    if g.cone_length is not None:  # the largest W0 over the face is at the open end (docs/models.md 3.1, coning)
        w0 *= g.cone_length / (g.cone_length - g.generator_z)
    sgn = -1.0 if design.external else 1.0  # +: flexspline teeth point outward
    depth = sgn * (f[0] + sgn * w0 - b[0])
    if depth > 0:
        return
    need = w0 - depth  # the W0 at which the tips would just touch
    if need / design.module > 5.0:  # beyond the w0_coef bound: the tooth counts are the cause
        raise DesignError(
            "drive.z_rigid",
            f"the teeth never meet: the flexspline tips stay {-depth:.4f} mm short of the rigid "
            f"tips on the major axis, and no W0 within the bound (5 m) closes the gap; "
            "bring z_rigid near z_flex",
        )
    raise DesignError(
        "generator.w0_coef",
        f"the teeth never meet: the flexspline tips stay {-depth:.4f} mm short of the rigid "
        f"tips on the major axis; W0 must exceed {need:.4f} mm (w0_coef > {need / design.module:.4f})",
    )


def build_drive(
    design: Design,
    tol: float = constants.CHORD_TOL,
    *,
    max_memory_mb: float | None = DEFAULT_MAX_MEMORY_MB,
    run: RunShape = RunShape(exports=False),
    rigid_gear: Gear | None = None,
) -> Drive:
    """Build both gears and the deformation law, checking the derived geometry.

    ``rigid_gear``: a conjugate design's rigid gear, already enveloped (:meth:`Drive.sampled_at`: the same curves at
    another tolerance); without it the envelope is built (once per design and tolerance in a process).

    Before any outline is sampled the run is estimated
    (:func:`wgcad.design.budget.estimate_run`, with ``run`` its audit and
    exports; the default: the outlines alone) and refused if it would exceed ``max_memory_mb``
    (None: no limit); an audit is checked again with the built gears' own
    vertex counts.

    Raises
    ------
    DesignError
        A derived-geometry rule is broken (names the field to change), or
        the run exceeds the memory budget (names ``--max-memory-mb``).
    """
    if not tol > 0:
        raise DesignError("chord_tol", f"must be > 0, got {tol:g}")
    # the outlines first, from the upper estimate of their vertex counts; the audit's arrays
    # (which dwarf the outlines) once the gears give their own counts, before the audit starts
    check_budget(estimate_run(design, tol, run=replace(run, angles=0)), max_memory_mb)
    flex = make_gear(tooth_spec(design, "flexspline"), tol)
    rigid = make_gear(tooth_spec(design, "rigid"), tol)
    _check_teeth_meet(design)  # after each gear's own rules, which name the field to change first
    if run.angles:
        counts = {"flexspline": len(flex.period) - 1, "rigid": len(rigid.period) - 1}
        check_budget(estimate_run(design, tol, run=run, vertices_per_tooth=counts), max_memory_mb)
    h1 = design.flexspline.rim_thickness
    if design.external:
        # internal-toothed flexspline: rim outside its root circle
        r_m = flex.r_f + 0.5 * h1
        flex_rim = flex.r_f + h1
        rigid_rim = rigid.r_f - design.rigid.rim_thickness
        if rigid_rim <= 0:
            raise DesignError(
                "rigid.rim_thickness",
                f"{design.rigid.rim_thickness:g} mm leaves no bore inside the root circle {rigid.r_f:.4f} mm",
            )
    else:
        r_m = flex.r_f - 0.5 * h1
        flex_rim = flex.r_f - h1
        rigid_rim = rigid.r_f + design.rigid.rim_thickness
        if flex_rim <= 0:
            raise DesignError(
                "flexspline.rim_thickness", f"{h1:g} mm leaves no bore inside the root circle {flex.r_f:.4f} mm"
            )
    g = design.generator
    law = make_law(
        g.law,
        w0=design.w0,
        r_m=r_m,
        n_waves=design.drive.waves,
        beta=None if g.beta_deg is None else float(np.deg2rad(g.beta_deg)),
        offset=g.offset,
    )
    drive = Drive(design, flex, rigid, law, float(r_m), float(flex_rim), float(rigid_rim), tol)
    if drive.face_taper:  # the centre section's law carries its teeth's offset like every other section's
        drive = replace(drive, law=replace(law, tooth_offset=drive.tooth_offset(None)))
    if design.rigid.flanks == "conjugate":
        drive = replace(drive, rigid=rigid_gear) if rigid_gear is not None else _conjugate(drive)
    return drive


#: the last few conjugate rigid gears built, by (design, chord tolerance): a design's commands run in one process
#: (the library's callers, the synthesis's neighbours, the tests) build its envelope once; the gears are frozen
_CONJUGATES: OrderedDict = OrderedDict()
_CONJUGATES_KEPT = 4


def _conjugate(drive: Drive) -> Drive:
    """The drive with its rigid gear's flanks made conjugate to the flexspline's teeth (docs/models.md 13)."""
    key = (drive.design, drive.tol)
    if key in _CONJUGATES:
        _CONJUGATES.move_to_end(key)
        return replace(drive, rigid=_CONJUGATES[key])
    drive = _build_conjugate(drive)
    _CONJUGATES[key] = drive.rigid
    while len(_CONJUGATES) > _CONJUGATES_KEPT:
        _CONJUGATES.popitem(last=False)
    return drive


def _build_conjugate(drive: Drive) -> Drive:
    d = drive.design
    z = d.rigid.conjugate_z
    if z is None:
        z = d.generator.generator_z if drive.coned else 0.5 * d.drive.face_width
    try:
        gear, _ = conjugate_rigid_gear(drive, z if drive.coned else None, 1e-3 * d.rigid.conjugate_clearance_um)
    except ValueError as e:
        raise DesignError("rigid.flanks", f"cannot be made conjugate: {e}") from None
    return replace(drive, rigid=gear)
