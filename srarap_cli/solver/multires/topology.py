"""Topological invariants of a triangle mesh, to check that simplification kept them."""

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ..mesh_checks import distinct_ids, edge_counts


def topology_summary(F: np.ndarray, n: int) -> dict[str, int | bool]:
    """Counts that a genus-preserving simplification must keep.

    Parameters
    ----------
    F : (f, 3) int array
    n : int, number of vertices (unreferenced ones are not counted)

    Returns
    -------
    dict with ``euler`` (V - E + F over referenced vertices), ``components``,
    ``boundary_loops`` (connected pieces of the boundary) and ``edge_manifold``
    (no edge in more than two triangles)

    Examples
    --------
    >>> topology_summary(np.array([[0, 1, 2], [0, 2, 3]]), 4)["boundary_loops"]
    1
    """
    F = np.asarray(F, dtype=np.int64)
    edges, count = edge_counts(F)
    used = distinct_ids(F, n)
    adj = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    components = csgraph.connected_components(adj, directed=False)[1][used]
    border = edges[count == 1]
    loops = 0
    if len(border):
        badj = sp.coo_matrix((np.ones(len(border)), (border[:, 0], border[:, 1])), shape=(n, n))
        labels = csgraph.connected_components(badj, directed=False)[1]
        loops = distinct_ids(labels[distinct_ids(border, n)], n).size
    return {"euler": int(used.size - len(edges) + len(F)),
            "components": int(distinct_ids(components, n).size),
            "boundary_loops": int(loops), "edge_manifold": bool(count.max(initial=0) <= 2)}
