"""Simplify a triangle mesh to a triangulation of a SUBSET of its own vertices.

Quadric-error half-edge collapses (:mod:`.collapse`): every collapse deletes one vertex and
hands its triangles to a neighbour, so each coarse vertex sits exactly on a fine vertex and
the coarse-to-fine map is exact, never a nearest-vertex guess (the paper's reference
implementation used MeshLab's collapse with optimal placement off for the same reason).
Borders slide only along themselves, the link condition keeps the surface manifold, and no
collapse flips a triangle.
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...runtime.warning_codes import note
from .collapse import collapse_to
from .topology import topology_summary


@dataclass
class CoarseMesh:
    """A simplified mesh whose vertices are fine vertices.

    Attributes
    ----------
    vertices : (m,) int array, sorted fine ids of the coarse vertices
    faces : (g, 3) int array, triangles indexing ``vertices``
    warnings : list of str
    """

    vertices: np.ndarray
    faces: np.ndarray
    warnings: list


def simplify_to_subset(V: np.ndarray, F: np.ndarray, size: int,
                       groups: Sequence[np.ndarray] = ()) -> CoarseMesh:
    """Quadric-error half-edge collapses of (V, F) down to about ``size`` vertices.

    Every group keeps at least one coarse vertex: its vertex nearest the group's centroid
    never collapses.

    Parameters
    ----------
    V : (n, 3) float array
    F : (f, 3) int array
    size : int, wanted number of coarse vertices
    groups : sequence of (j,) int arrays, fine ids that must keep a representative

    Returns
    -------
    CoarseMesh

    Examples
    --------
    >>> import igl
    >>> V, F = igl.loop(*_octahedron())
    >>> c = simplify_to_subset(V, F, 10, groups=[np.array([0])])
    >>> bool(np.all(np.isin([0], c.vertices))), bool(len(c.vertices) < len(V))
    (True, True)
    """
    V = np.ascontiguousarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    groups = [g[used[g]] for g in map(np.asarray, groups)]
    frozen = np.zeros(len(V), dtype=bool)
    frozen[[_representative(V, g) for g in groups if g.size]] = True
    faces = collapse_to(V, F, max(int(size), 4), frozen)
    vertices, faces = np.unique(faces, return_inverse=True)
    faces = faces.reshape(-1, 3)
    notes = _topology_warnings(F, faces, len(V), len(vertices))
    if len(vertices) > 1.5 * size and len(vertices) < used.sum():
        notes.append(note("coarse-size", f"simplification stopped at {len(vertices)} vertices "
                          f"(asked {size}): no further collapse keeps the surface valid"))
    return CoarseMesh(vertices, faces, notes)


def _representative(V, group):
    """The group's vertex nearest its centroid."""
    return group[np.argmin(np.sum((V[group] - V[group].mean(axis=0)) ** 2, axis=1))]


def _topology_warnings(F, G, n, m):
    fine, coarse = topology_summary(F, n), topology_summary(G, m)
    notes = []
    if fine["edge_manifold"] and not coarse["edge_manifold"]:
        notes.append(note("coarse-topology", "the coarse mesh has non-manifold edges"))
    for key, what in (("euler", "Euler characteristic"), ("components", "connected parts"),
                      ("boundary_loops", "boundary loops")):
        if fine[key] != coarse[key]:
            notes.append(note("coarse-topology", f"the coarse mesh's {what} differ from the "
                              f"mesh's ({coarse[key]} vs {fine[key]})"))
    return notes


def _octahedron():
    V = np.array([[1., 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return V, F
