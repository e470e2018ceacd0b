"""Restrict a solve to a region of interest: only the faces it touches are solved."""
from dataclasses import dataclass

import numpy as np

from .mesh_checks import distinct_ids


@dataclass
class Submesh:
    """The part of a mesh a region-limited solve works on.

    Attributes
    ----------
    vertices : (s,) int array, ids in the full mesh of the submesh's vertices (sorted)
    faces : (f, 3) int array, triangles in submesh ids
    constrained : (k,) int array, submesh ids whose positions are prescribed
    targets : (k, 3) float array
    slots, which : int arrays, ``targets[slots] = constraint_targets[which]``; the other
        constrained submesh vertices stay at rest
    """

    vertices: np.ndarray
    faces: np.ndarray
    constrained: np.ndarray
    targets: np.ndarray
    slots: np.ndarray
    which: np.ndarray


def restrict(V: np.ndarray, F: np.ndarray, ids: np.ndarray, targets: np.ndarray, region: np.ndarray
             ) -> Submesh:
    """Cut out the triangles touching movable vertices (region minus constrained).

    Vertices of those triangles outside the region are held at rest, as CGAL's region of
    interest does; the rest of the mesh is not part of the solve at all.

    Parameters
    ----------
    V : (n, 3) float array
    F : (f, 3) int array
    ids : (k,) int array, sorted constrained ids
    targets : (k, 3) float array
    region : (r,) int array, vertices allowed to move

    Returns
    -------
    Submesh
    """
    movable = np.zeros(len(V), dtype=bool)
    movable[region] = True
    movable[ids] = False
    faces = F[movable[F].any(axis=1)]
    verts = distinct_ids(faces, len(V))
    local = np.full(len(V), -1)
    local[verts] = np.arange(verts.size)
    full_targets = V[verts].copy()
    in_sub = local[ids] >= 0
    full_targets[local[ids[in_sub]]] = targets[in_sub]
    fixed = np.flatnonzero(~movable[verts])
    which = np.flatnonzero(in_sub)
    slots = np.searchsorted(fixed, local[ids[which]])
    return Submesh(vertices=verts, faces=local[faces], constrained=fixed,
                   targets=full_targets[fixed], slots=slots, which=which)
