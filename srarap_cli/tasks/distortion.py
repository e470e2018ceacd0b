"""Per-vertex distortion of a deformed mesh against its rest shape."""
import numpy as np

from ..solver.closest_rotors import closest_rotors
from ..solver.operators import cell_graph
from ..solver.quaternion import IDENTITY, rotate
from ..solver.rest_edges import RestEdges


def vertex_distortion(rest: np.ndarray, deformed: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Relative local strain of every vertex cell: ``sqrt(e_i / sum_j c_ij |q_ij|^2)`` where
    ``e_i = min_R sum_j c_ij |R q_ij - p_ij|^2`` (the best-fit rotation's membrane residual).

    Zero for any rigid motion; about the relative edge-length change for small stretches.

    Parameters
    ----------
    rest, deformed : (n, 3) float arrays; F : (f, 3) int array

    Returns
    -------
    (n,) float array (0 for unreferenced vertices)

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> float(vertex_distortion(V, 2 * V, np.array([[0, 1, 2]])).max()) > 0.5
    True
    """
    g = cell_graph(rest, F)
    edges = RestEdges(g, rest)
    R = closest_rotors(edges.cross(deformed), np.tile(IDENTITY, (len(rest), 1)))
    residual = rotate(R[g.I], edges.q) - edges.deformed(deformed)
    e = g.cell_sum(g.c * np.einsum("ij,ij->i", residual, residual))
    scale = edges.rest_scale
    out = np.zeros(len(rest))
    ok = scale > 0
    out[ok] = np.sqrt(np.maximum(e[ok], 0) / scale[ok])
    return out


