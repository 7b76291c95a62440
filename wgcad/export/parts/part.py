"""One part of the drive's part set: its drawing, the recipes of its solid and mesh, and the volume they must have."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field

from ...records import record

__all__ = ["Part"]


@record
class Part:
    """One part of the drive.

    Attributes
    ----------
    name : str
        File-name stem, e.g. ``"flexspline"``.
    layers : list of DxfLayer
        Top-view drawing, incl. a ``GEAR_DATA`` text layer for gears.
    make_solid : callable -> OCP TopoDS_Shape
    make_mesh : callable -> wgcad.export.mesh.Mesh
    volume_mm3 : float
        Volume from the 2D areas (area x height, annuli, holes), computed
        without any 3D kernel.
    bounds : ((x0, y0, z0), (x1, y1, z1))
        Expected bounding box, mm.
    info : dict
        Sizes and figures reported for the part.
    make_brep : callable -> wgcad.export.brep.Brep or None, optional
        The solid as B-rep text without a CAD kernel (:mod:`wgcad.export.parts.breps`), ``None`` where its recipe
        does not apply; the STEP file is then made from :meth:`solid`.
    """

    name: str
    layers: list
    make_solid: Callable
    make_mesh: Callable
    volume_mm3: float
    bounds: tuple
    info: dict = field(default_factory=dict)
    make_brep: Callable | None = field(default=None, repr=False)
    _solid: object = field(default=None, repr=False)
    _mesh: object = field(default=None, repr=False)

    def solid(self):
        """The OCP solid (built once)."""
        if self._solid is None:
            self._solid = self.make_solid()
        return self._solid

    def brep(self):
        """The B-rep of the solid written without OpenCASCADE, or ``None`` (then :meth:`solid`)."""
        return self.make_brep() if self.make_brep is not None else None

    def mesh(self):
        """The mesh (built once)."""
        if self._mesh is None:
            self._mesh = self.make_mesh()
        return self._mesh
