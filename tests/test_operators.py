"""The cell graph's Laplacian against its weights, built densely."""
import numpy as np
import scipy.sparse as sp
from helpers import torus

from srarap_cli.solver.operators import cell_graph


def test_the_laplacian_is_made_from_the_weights_when_asked_for_and_not_held():
    V, F = torus(rings=8, segments=6)
    graph = cell_graph(V, F)
    W = np.zeros((graph.n, graph.n))
    W[graph.I, graph.J] = graph.c
    K = graph.laplacian
    assert np.allclose(K.toarray(), np.diag(W.sum(axis=1)) - W, rtol=0, atol=1e-13)
    assert np.allclose(K @ np.ones(graph.n), 0.0)
    # a solve holds its cell graph: no (n, n) matrix may ride along (0.12 GB at 1.2M)
    assert not any(sp.issparse(value) for value in vars(graph).values())
