"""The library's front door: each command of the CLI as one call that takes a design (a file's path, a
:class:`~wgcad.design.Design` or a built :class:`~wgcad.drive.Drive`) and returns a record, not files or tuples.

They are thin: each calls what its ``wgcad`` command calls (``wgcad/cli/*.py``) and keeps the objects the command
would only print or write. ``doc`` is always the JSON document of the command's ``--json``.

>>> import wgcad
>>> run = wgcad.audit("templates/d4_discrete.toml")        # wgcad audit
>>> run.doc["worst"]["min_clearance_um"], run.failed
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from .design import Design, load_design
from .drive import Drive, build_drive
from .errors import DesignError
from .services.audit import RunSettings

__all__ = ["audit", "load_audit", "kinematic_error", "rating", "parts", "LoadAudit", "Rating", "PartSet"]


def _design(design) -> Design:
    """A path is read, a Design taken as it is, a Drive gives the design it was built from."""
    if isinstance(design, Design):
        return design
    if isinstance(design, Drive):
        return design.design
    if isinstance(design, (str, os.PathLike)):
        return load_design(design)
    raise DesignError("design", f"expected a design file's path, a Design or a Drive, got {type(design).__name__}")


def _drive(design, chord_tol_um: float | None = None) -> Drive:
    """A Drive passed in is used as built (its tolerance), else one is built at ``chord_tol_um`` (default 1 um)."""
    if isinstance(design, Drive) and chord_tol_um is None:
        return design
    return build_drive(_design(design), tol=(1.0 if chord_tol_um is None else chord_tol_um) * 1e-3)


def audit(design, settings: RunSettings | None = None, *, engine: str = "2d", baseline=None, by_section=False):
    """The clearance audit over the generator cycle (``wgcad audit``): a :class:`wgcad.services.audit_report.AuditReport`
    with ``drive``, ``result`` (the findings: ``result.findings["min_clearance"].value`` in mm), ``doc`` and
    ``failed`` (interference or drift from ``baseline``, a :func:`wgcad.regression.load_baseline` dict: exit 1).

    ``settings`` default :class:`wgcad.audit.RunSettings` (0.5 degree steps, 1 um chords); ``engine`` "2d", "fcl"
    or "both" (the 3D check of the pairs the 2D engine singles out). A Drive is audited from its design, at the
    settings' chord tolerance (the audit builds its drive with its run's memory budget)."""
    from .services.audit_report import audit_document

    return audit_document(
        _design(design), settings or RunSettings(), engine=engine, baseline=baseline, by_section=by_section
    )


@dataclass(slots=True)
class LoadAudit:
    """The load audit of a drive: the drive and ``doc``, the document of ``wgcad audit --torque-nm --json``
    (``doc["levels"]``: per torque the entry gap, the contact zone, the tooth forces, the stiffness)."""

    drive: Drive
    doc: dict


def load_audit(design, torque_nm, *, cam_offset_um=None, cam_offset_deg=None, sections: int = 3) -> LoadAudit:
    """The teeth under load (``wgcad audit --torque-nm``): the elastic model solved at each torque of
    ``torque_nm`` (a number or a sequence, N m); the cam offset defaults to the design's ``[load]``."""
    from .report.load import load_run

    torques = [float(t) for t in (torque_nm if hasattr(torque_nm, "__iter__") else [torque_nm])]
    drive, doc = load_run(_design(design), torques, cam_offset_um, cam_offset_deg, sections)
    return LoadAudit(drive, doc)


def kinematic_error(
    design,
    imperfections=None,
    *,
    per_mesh: int = 16,
    torque_nm=None,
    optimize_install_angle: bool = False,
    chord_tol_um: float | None = None,
):
    """The kinematic error (``wgcad ke``): a :class:`wgcad.services.ke.KERun` with ``res`` (``res.ke``: the KE
    in rad at each angle, ``res.ke_pp``), the spectrum (``orders``, ``amp``) and ``doc``.

    ``imperfections`` (:class:`wgcad.placement.imperfect.Imperfections`) default the design's
    ``[imperfections]``; ``torque_nm`` (sequence, each > 0) adds the KE under load (``run.loaded``);
    ``optimize_install_angle`` the installation-angle scan (``run.scan``)."""
    from .placement.imperfect import Imperfections
    from .services.ke import add_install_scan, add_loaded, no_load

    drive = _drive(design, chord_tol_um)
    imp = Imperfections.from_spec(drive.design.imperfections) if imperfections is None else imperfections
    run, _ = no_load(drive, imp, per_mesh, drive.design.source or drive.design.drive.name)
    if torque_nm is not None:
        torques = [float(t) for t in (torque_nm if hasattr(torque_nm, "__iter__") else [torque_nm])]
        if any(t <= 0 for t in torques):
            raise DesignError("torque_nm", "the loaded KE needs torques > 0 N m (no load is the KE without it)")
        add_loaded(run, torques, install=optimize_install_angle)
    if optimize_install_angle:
        add_install_scan(run)
    return run


@dataclass(slots=True)
class Rating:
    """A drive's datasheet (``wgcad rating``): ``datasheet`` (:class:`wgcad.rating.Datasheet`: ``rated_torque_nm``,
    the binding criterion, stiffness, levels) and ``doc``, the document of ``wgcad rating --json``."""

    drive: Drive
    datasheet: object
    doc: dict


def rating(design, *, speed_rpm: float | None = None, sections: int = 3, cam_offset=None) -> Rating:
    """Rate the drive as a catalogue does (``wgcad rating``): needs ``[bearing]`` and ``[material]
    ultimate_strength_mpa``. ``speed_rpm`` and ``cam_offset`` (``(um, deg)``) replace the design's ``[load]``."""
    from .rating.datasheet import rate_drive
    from .report.rating import rating_document

    drive = _drive(design)
    ds = rate_drive(drive, speed_rpm=speed_rpm, sections=sections, cam_offset=cam_offset)
    return Rating(drive, ds, rating_document(ds, drive.design.source or ""))


@dataclass(slots=True)
class PartSet:
    """The parts a shop makes (``wgcad parts``): ``parts`` (each with ``name``, ``info`` and ``solid()``, the
    build123d shape; :mod:`wgcad.cad` gives them labelled, with named faces), the sizes used (``sizes.values``,
    ``sizes.derived``: those not given in ``[parts]``), and, when written, ``report`` (``<design>_parts.json``) and
    ``files``."""

    drive: Drive
    sizes: object
    parts: list
    report: dict | None = None
    files: list | None = None

    def names(self) -> list[str]:
        return [p.name for p in self.parts]


def parts(design, out=None, *, formats=None, dxf_style: str = "arcs", generator_angles_deg=(), chord_tol_um=None):
    """The part set of a design with its ``[parts]`` sizes (derived where not given): built, and with ``out`` (a
    folder) written there in ``formats`` (default every one: dxf, svg, stl, 3mf, step; STEP needs ``[cad]``).
    Sizes come from the design file's ``[parts]`` table, so ``design`` is a path or a Design read from one."""
    from .design.parts import load_parts
    from .export.files.parts import FORMATS, write_part_files
    from .export.parts import build_parts
    from .rating.plate_sizing import sized_parts

    loaded = _design(design)
    if not loaded.source:
        raise DesignError("design", "the part sizes are read from the design file's [parts]: give its path")
    drive = _drive(design, chord_tol_um)
    sizes = sized_parts(load_parts(loaded.source), drive)
    if out is None:
        built = build_parts(
            drive, sizes, style=dxf_style, tol=drive.tol, generator_angles_deg=list(generator_angles_deg)
        )
        return PartSet(drive, sizes, built)
    res = write_part_files(
        drive,
        sizes,
        loaded.source,
        out,
        formats=list(FORMATS if formats is None else formats),
        dxf_style=dxf_style,
        generator_angles_deg=generator_angles_deg,
    )
    return PartSet(drive, sizes, res.parts, res.report, res.files)
