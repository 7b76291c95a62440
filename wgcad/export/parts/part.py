"""One part of the drive's part set: its drawing, its one recipe (the bodies it is made of) and the volume they must
have; its solid and its mesh both derive from the recipe."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Part"]


@dataclass(slots=True)
class Part:
    """One part of the drive.

    Attributes
    ----------
    name : str
        File-name stem, e.g. ``"flexspline"``.
    layers : list of DxfLayer
        Top-view drawing, incl. a ``GEAR_DATA`` text layer for gears.
    bodies : dict
        The recipe: member name -> tuple of :class:`~wgcad.export.parts.recipe.Body` (a part has one member of one
        body, named as the part; the deformed assembly one member per body of the drive, the coned flexspline in
        axial slices).
    volume_mm3 : float
        Volume from the 2D areas (area x height, annuli, holes), computed
        without any 3D kernel.
    bounds : ((x0, y0, z0), (x1, y1, z1))
        Expected bounding box, mm.
    info : dict
        Sizes and figures reported for the part.
    """

    name: str
    layers: list
    bodies: dict
    volume_mm3: float
    bounds: tuple
    info: dict = field(default_factory=dict)
    _solid: object = field(default=None, repr=False)
    _meshes: dict = field(default_factory=dict, repr=False)

    def solid(self):
        """The build123d shape (built once): a ``Part`` labelled with the part's name, its faces named
        (``named_faces``); for several members a ``Compound`` of them, each labelled with its member's name."""
        if self._solid is None:
            from .kernel import require, solid

            members = {}
            for member, bodies in self.bodies.items():
                shapes = [solid(b, member) for b in bodies]
                if len(shapes) == 1:
                    members[member] = shapes[0]
                else:
                    members[member] = require().Compound(children=shapes, label=member)
            if list(members) == [self.name]:
                self._solid = members[self.name]
            else:
                self._solid = require().Compound(children=list(members.values()), label=self.name)
        return self._solid

    def member_meshes(self) -> dict:
        """Member name -> its mesh (built once; several bodies of a member joined by manifold3d)."""
        if not self._meshes:
            from .recipe import mesh

            for member, bodies in self.bodies.items():
                meshes = [mesh(b) for b in bodies]
                self._meshes[member] = meshes[0] if len(meshes) == 1 else _union(meshes)
        return self._meshes

    def mesh(self):
        """All members in one mesh (each a closed shell of its own)."""
        from ..formats.mesh import concatenate

        meshes = list(self.member_meshes().values())
        return meshes[0] if len(meshes) == 1 else concatenate(meshes)


def _union(meshes):
    """One closed mesh of touching or overlapping closed meshes (manifold3d's union, float64)."""
    import manifold3d
    import numpy as np

    from .solids import to_mesh

    out = None
    for m in meshes:
        mf = manifold3d.Manifold(
            manifold3d.Mesh64(vert_properties=np.ascontiguousarray(m.vertices), tri_verts=m.faces.astype(np.uint32))
        )
        out = mf if out is None else out + mf
    return to_mesh(out)
