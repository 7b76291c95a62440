"""The part set as build123d objects, to keep modelling with: the cup flexspline (or flexible ring), the rigid gear,
the plug (or generator ring) and the deformed assembly, in mm, the very shapes ``wgcad parts`` writes as STEP.

Each part is a build123d ``Part`` labelled with its name; ``part.named_faces`` maps the roles of its faces
(``teeth``, ``bore``, ``rim``, ``flange``, ``flange_face``, ``bolt_holes``, ``seat``, ``end``, ...) to ``ShapeList``\\ s
of them, and ``part.wgcad`` is the part's entry of ``DESIGN_parts.json`` (its volume and the bound it is known to,
sizes, gear data). The deformed assembly is a ``Compound`` of its members ``rigid``, ``flexspline`` (a ``Compound``
of axial slices where the flexspline is coned) and ``plug``, each labelled. build123d's own operations (fillets,
booleans, its exporters) apply as to any other shape; needs the extra: ``pip install 'wgcad[cad]'``.

>>> from wgcad import cad
>>> rigid = cad.part_set("templates/d4_discrete.toml")["rigid"]
>>> teeth = rigid.named_faces["teeth"]
"""

from __future__ import annotations

__all__ = ["part_set", "flexspline", "rigid", "plug", "assembly", "faces"]


def _parts(design, tol_mm, generator_angles_deg) -> list:
    """The part set's recipes (nothing built in 3D yet)."""
    from wgcad.design import load_design
    from wgcad.design.parts import load_parts
    from wgcad.drive import build_drive
    from wgcad.export.parts import build_parts
    from wgcad.export.parts.kernel import require
    from wgcad.rating.plate_sizing import sized_parts

    require()
    loaded = load_design(design)
    drive = build_drive(loaded) if tol_mm is None else build_drive(loaded, tol=tol_mm)
    sizes = sized_parts(load_parts(design), drive)
    return build_parts(drive, sizes, tol=drive.tol, generator_angles_deg=list(generator_angles_deg))


def _shape(part):
    """The part's build123d shape with its entry of the parts JSON as ``wgcad``."""
    from wgcad.report.parts import part_report

    shape = part.solid()
    shape.wgcad = part_report(part)
    return shape


def part_set(design, tol_mm: float | None = None, generator_angles_deg=()) -> dict:
    """Every part of the design file ``design`` (its ``[parts]`` sizes, derived where not given), name -> shape:
    ``flexspline``, ``rigid``, ``plug`` (external deformation: ``generator_ring``) and one
    ``assembly_phi...`` per generator angle (degrees). ``tol_mm``: the chord tolerance (default the design's)."""
    return {p.name: _shape(p) for p in _parts(design, tol_mm, generator_angles_deg)}


def _one(design, tol_mm, names, angles=()):
    return _shape(next(p for p in _parts(design, tol_mm, angles) if p.name.startswith(names)))


def flexspline(design, tol_mm: float | None = None):
    """The cup flexspline (external deformation: the toothed flexible ring) of the design file ``design``."""
    return _one(design, tol_mm, "flexspline")


def rigid(design, tol_mm: float | None = None):
    """The rigid gear with its flange (plain, sectored or conjugate, as the design builds it)."""
    return _one(design, tol_mm, "rigid")


def plug(design, tol_mm: float | None = None):
    """The wave-generator plug (external deformation: the generator ring)."""
    return _one(design, tol_mm, ("plug", "generator_ring"))


def assembly(design, generator_angle_deg: float = 0.0, tol_mm: float | None = None):
    """The deformed assembly at one generator angle (degrees, counter-clockwise, relative to the fixed member)."""
    return _one(design, tol_mm, "assembly", (generator_angle_deg,))


def faces(shape, role: str):
    """The faces of ``shape`` (a part of this module) that play ``role``, e.g. ``faces(rigid, "flange_face")``."""
    named = getattr(shape, "named_faces", None)
    if named is None:
        raise ValueError(f"{shape.label or 'this shape'} has no named faces (a member of an assembly has them)")
    if role not in named:
        raise KeyError(f"{role!r}: not a face role of {shape.label} (roles: {', '.join(named)})")
    return named[role]
