"""The polygon mesh record every reader fills and every writer consumes."""
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike


@dataclass
class Mesh:
    """A polygon mesh as read from a file, kept close to the file's own structure.

    Attributes
    ----------
    vertices : (n, 3) float array, in file order
    face_sizes : (k,) int array, corners per polygon
    face_vertices : (c,) int array, corner vertex ids, polygons one after another
    uv : (t, d) float array or None, texture coordinates (OBJ ``vt``, PLY ``s t``)
    face_uv : (c,) int array or None, per-corner index into ``uv`` (-1 where a corner has none)
    normals : (m, 3) float array or None
    face_normals : (c,) int array or None, per-corner index into ``normals`` (-1: none)
    vertex_data : dict of name -> (n,) array, other per-vertex properties (PLY)
    statements : list of (int, str), OBJ lines kept verbatim (``mtllib``, ``usemtl``, ``g``,
        ``s``, ...) with the number of faces that preceded them
    unkept : list of str, what the file held that no writer keeps (PLY face properties,
        other PLY elements): every written file warns of it
    """

    vertices: np.ndarray
    face_sizes: np.ndarray
    face_vertices: np.ndarray
    uv: np.ndarray | None = None
    face_uv: np.ndarray | None = None
    normals: np.ndarray | None = None
    face_normals: np.ndarray | None = None
    vertex_data: dict = field(default_factory=dict)
    statements: list = field(default_factory=list)
    unkept: list[str] = field(default_factory=list)

    @classmethod
    def from_arrays(cls, V: ArrayLike, F: np.ndarray | Sequence[ArrayLike]) -> "Mesh":
        """A mesh of positions ``V`` (n, 3) and faces ``F``: an (f, k) int array of k-gons,
        or a list of vertex-id sequences of any sizes.

        Examples
        --------
        >>> m = Mesh.from_arrays([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
        >>> m.face_sizes.tolist(), m.triangles()[0].tolist()
        ([4], [[0, 1, 2], [0, 2, 3]])
        """
        V = np.asarray(V, dtype=float)
        if V.ndim != 2 or V.shape[1] != 3:
            raise ValueError(f"V must be an (n, 3) array of positions, got shape {V.shape}")
        faces = [np.asarray(f).ravel() for f in F] if not isinstance(F, np.ndarray) \
            else list(F.reshape(len(F), -1))
        if not faces or any(len(f) < 3 for f in faces):
            raise ValueError("F must list faces of 3 or more vertex ids")
        corners = np.concatenate(faces)
        if corners.dtype.kind not in "iu":
            raise ValueError(f"F must hold integer vertex ids, got dtype {corners.dtype}")
        if corners.min() < 0 or corners.max() >= len(V):
            raise ValueError(f"F: vertex id out of range for V of {len(V)} rows")
        return cls(vertices=V, face_sizes=np.array([len(f) for f in faces], dtype=np.int64),
                   face_vertices=corners.astype(np.int64))

    @property
    def face_offsets(self) -> np.ndarray:
        """(k + 1,) cumulative corner offsets: polygon f is ``face_vertices[o[f]:o[f+1]]``."""
        return np.concatenate([[0], np.cumsum(self.face_sizes)]).astype(np.int64)

    def triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """Fan triangulation for the solve: ``F`` (f, 3) and the polygon of each triangle."""
        if self.face_sizes.size and self.face_sizes.min() == self.face_sizes.max() == 3:
            return self.face_vertices.reshape(-1, 3), np.arange(self.face_sizes.size)
        from ...solver.libigl import igl  # loads scipy: not needed to read or write a file

        F, J = igl.polygons_to_triangles(self.face_vertices.astype(np.int64), self.face_offsets)
        return F, J

    def with_vertices(self, vertices: ArrayLike) -> "Mesh":
        """A copy with new positions and normals recomputed for them."""
        from .normals import recompute_normals
        out = Mesh(**{k: getattr(self, k) for k in self.__dataclass_fields__})
        out.vertices = np.asarray(vertices, dtype=float)
        if out.normals is not None:
            out.normals = recompute_normals(out)
        return out
