"""A triangle mesh as two arrays, with the checks and figures the exporters need (numpy only).

The solids are built by manifold3d; what the exporters need of the result is
its vertices and faces, whether it is a closed, consistently oriented volume,
its volume and bounds, and a binary STL. trimesh (not a dependency of wgcad;
the tests read the files back with it, an independent reader) would give
them at a cost of 37 % of the CPU of ``wgcad generate d1_involute`` and
17 % of ``wgcad parts`` (STL and 3MF), even imported only where the STL is
written (benchmarks/copies.py, ``mesh``): a copy kept by
docs/architecture.md's rule. (trimesh's 3MF writer would need networkx too.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["Mesh", "concatenate"]


class Mesh:
    """Vertices ``(V, 3)`` float64 (mm) and faces ``(F, 3)`` int64, counter-clockwise seen from outside."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)

    @property
    def triangles(self) -> np.ndarray:
        """``(F, 3, 3)`` corner coordinates."""
        return self.vertices[self.faces]

    @property
    def face_normals(self) -> np.ndarray:
        """Unit normals ``(F, 3)`` (zero for a degenerate face)."""
        t = self.triangles
        n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        norm = np.linalg.norm(n, axis=1)
        return np.divide(n, norm[:, None], out=np.zeros_like(n), where=norm[:, None] > 0)

    @property
    def volume(self) -> float:
        """Enclosed volume (mm^3), by the divergence theorem: positive for an outward-oriented closed mesh.

        The corners are taken about the mesh's centre, which keeps the
        rounding of a part 80 mm from the origin at the level of one about
        its own centre.
        """
        if len(self.faces) == 0:
            return 0.0
        t = self.triangles - self.vertices.mean(axis=0)
        return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)

    @property
    def bounds(self) -> np.ndarray:
        """``[[xmin, ymin, zmin], [xmax, ymax, zmax]]``."""
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def _edge_keys(self) -> tuple[np.ndarray, np.ndarray]:
        """Sorted int64 keys of the directed edges ``a V + b`` and of the undirected ones ``min V + max``."""
        f = self.faces
        a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
        b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
        n = max(len(self.vertices), 1)
        return np.sort(a * n + b), np.sort(np.minimum(a, b) * n + np.maximum(a, b))

    @staticmethod
    def _run_lengths(sorted_keys: np.ndarray) -> np.ndarray:
        cut = np.flatnonzero(np.diff(sorted_keys)) + 1
        return np.diff(np.concatenate([[0], cut, [len(sorted_keys)]]))

    @property
    def is_watertight(self) -> bool:
        """Every edge is shared by exactly two faces."""
        if len(self.faces) == 0:
            return False
        return bool(np.all(self._run_lengths(self._edge_keys()[1]) == 2))

    @property
    def is_winding_consistent(self) -> bool:
        """No two faces walk an edge the same way (so the faces either side of an edge agree on which side is out)."""
        if len(self.faces) == 0:
            return False
        return bool(np.all(self._run_lengths(self._edge_keys()[0]) == 1))

    @property
    def euler_number(self) -> int:
        """``V - E + F`` (2 for a closed shell without handles; a ring with a bore has 0)."""
        edges = len(self._run_lengths(self._edge_keys()[1])) if len(self.faces) else 0
        return int(len(np.unique(self.faces)) - edges + len(self.faces))

    @property
    def is_volume(self) -> bool:
        """Closed, consistently wound and outward (positive volume): a solid a slicer or CAD kernel accepts."""
        if len(self.faces) == 0:
            return False
        directed, undirected = self._edge_keys()
        closed = np.all(self._run_lengths(undirected) == 2)
        return bool(closed and np.all(self._run_lengths(directed) == 1) and self.volume > 0.0)

    def stl_bytes(self, header: bytes) -> bytes:
        """Binary STL: the 80-byte ``header`` (NUL-padded), the triangle count, then per triangle its float32 normal,
        its three float32 corners and a zero attribute word. Deterministic for the same mesh."""
        rec = np.zeros(
            len(self.faces),
            dtype=np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")]),
        )
        rec["normal"] = self.face_normals
        rec["corners"] = self.triangles
        head = header[:80].ljust(80, b"\0") + np.uint32(len(self.faces)).astype("<u4").tobytes()
        return head + rec.tobytes()


def concatenate(meshes) -> Mesh:
    """One mesh of several (faces renumbered; the parts stay separate shells)."""
    verts, faces, at = [], [], 0
    for m in meshes:
        verts.append(m.vertices)
        faces.append(m.faces + at)
        at += len(m.vertices)
    return Mesh(np.concatenate(verts), np.concatenate(faces))
