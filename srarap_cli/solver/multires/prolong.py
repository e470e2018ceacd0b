"""Carry a coarse solution to the full mesh as a start for full-resolution iterations.

The paper's transfer (section 7.1) pins the fine positions at the coarse vertices and spreads
the coarse rotors harmonically between them. As a *start* that is poor: point Dirichlet values
make the rotor field spike at every coarse vertex, and the transferred shape had 0.7-1.7x the
minimum energy above the minimum on the decimated Max bust (worse than Laplacian editing, 0.2x).
Here every vertex instead follows its nearest coarse vertex rigidly (``p'_k + R_k (v - v_k)``,
nearest by distance along the mesh's edges), a piecewise rigid shape whose seams the first
local/global step closes: 1-4% above the minimum on the same case.
"""

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from ..quaternion import IDENTITY, rotate
from ..rest_edges import RestEdges


def nearest_coarse(edges: RestEdges, coarse_vertices: np.ndarray) -> np.ndarray:
    """Index (into ``coarse_vertices``) of each vertex's nearest coarse vertex along the
    mesh's edges; -1 where none is reachable (a part of the mesh with no coarse vertex).

    Parameters
    ----------
    edges : RestEdges of the mesh (its graph's directed edges and their rest lengths)
    coarse_vertices : (c,) int array

    Returns
    -------
    (n,) int array

    Examples
    --------
    >>> from ..operators import cell_graph
    >>> from ..rest_edges import RestEdges
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0]])
    >>> F = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
    >>> nearest_coarse(RestEdges(cell_graph(V, F), V), np.array([0, 5])).tolist()
    [0, 0, 1, 0, 1, 1]
    """
    graph = edges.graph
    n = graph.n
    # a zero-length edge would read as "no edge" in a sparse matrix
    length = np.maximum(np.sqrt(edges.q_sq), np.finfo(float).tiny)
    G = sp.csr_matrix((length, (graph.I, graph.J)), shape=(n, n))
    _, _, source = dijkstra(G, directed=False, indices=coarse_vertices, min_only=True,
                            return_predecessors=True)
    slot = np.full(n, -1)
    slot[coarse_vertices] = np.arange(len(coarse_vertices))
    return np.where(source >= 0, slot[np.maximum(source, 0)], -1)


def prolong(V: np.ndarray, nearest: np.ndarray, coarse_vertices: np.ndarray, coarse_positions: np.ndarray,
            coarse_rotors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The piecewise rigid full-resolution shape of a coarse solution.

    Parameters
    ----------
    V : (n, 3) float array, rest positions of the full mesh
    nearest : (n,) int array, from :func:`nearest_coarse`
    coarse_vertices : (c,) int array; coarse_positions : (c, 3); coarse_rotors : (c, 4)

    Returns
    -------
    P : (n, 3) float array, ``p'_k + R_k (v - v_k)`` for the nearest coarse vertex ``k``
        (rest position where there is none)
    R : (n, 4) float array, ``R_k`` (identity where there is none)

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0]])
    >>> half_turn_z = np.array([[0., 0, 0, 1]])
    >>> P, R = prolong(V, np.array([0, 0]), np.array([0]), np.array([[5., 0, 0]]), half_turn_z)
    >>> np.round(P, 12).tolist()
    [[5.0, 0.0, 0.0], [4.0, 0.0, 0.0]]
    """
    reached = nearest >= 0
    k = nearest[reached]
    P = np.array(V, dtype=float)
    R = np.tile(IDENTITY, (len(V), 1))
    R[reached] = coarse_rotors[k]
    P[reached] = coarse_positions[k] + rotate(R[reached], V[reached] - V[coarse_vertices[k]])
    return P, R
