"""Normals of a deformed polygon mesh, following the input's own normal sharing."""
from typing import Protocol

import numpy as np


class PolygonMesh(Protocol):
    """What the normals need of a :class:`~srarap_cli.io.mesh.mesh.Mesh` (which computes its
    normals with this module, so it is not imported here)."""

    vertices: np.ndarray
    face_sizes: np.ndarray
    face_vertices: np.ndarray
    normals: np.ndarray | None
    face_normals: np.ndarray | None

    @property
    def face_offsets(self) -> np.ndarray: ...


def polygon_normals(mesh: PolygonMesh) -> np.ndarray:
    """Area-weighted (Newell) normal of every polygon: (k, 3), length = twice the area."""
    offsets = mesh.face_offsets
    corner = np.arange(mesh.face_vertices.size)
    nxt = corner + 1
    ends = offsets[1:] - 1
    nxt[ends] = offsets[:-1]
    a = mesh.vertices[mesh.face_vertices]
    b = mesh.vertices[mesh.face_vertices[nxt]]
    cross = np.cross(a, b)
    face_of_corner = np.repeat(np.arange(mesh.face_sizes.size), mesh.face_sizes)
    out = np.zeros((mesh.face_sizes.size, 3))
    np.add.at(out, face_of_corner, cross)
    return out


def recompute_normals(mesh: PolygonMesh) -> np.ndarray | None:
    """New ``normals`` (m, 3) for ``mesh.vertices``.

    Each normal becomes the normalized sum of the area-weighted normals of the polygons whose
    corners reference it, so a file's smooth or split (per-corner) normals stay smooth or
    split. Normals no corner references are kept as they were.
    """
    if mesh.normals is None or mesh.face_normals is None:
        return mesh.normals
    normals = np.array(mesh.normals, dtype=float, copy=True)
    used = mesh.face_normals >= 0
    face_of_corner = np.repeat(np.arange(mesh.face_sizes.size), mesh.face_sizes)
    acc = np.zeros_like(normals)
    np.add.at(acc, mesh.face_normals[used], polygon_normals(mesh)[face_of_corner[used]])
    length = np.linalg.norm(acc, axis=1)
    ok = length > 0
    normals[ok] = acc[ok] / length[ok, None]
    return normals
