"""Rest-shape edge data as sparse operators, so per-iteration sums are sparse products."""
import numpy as np
import scipy.sparse as sp

from .quaternion import to_matrix


class RestEdges:
    """Rest edges ``q_ij = q_j - q_i`` of a cell graph, precomputed for the loop.

    Attributes
    ----------
    q : (m, 3) float array; q_sq : (m,) float array
    sum_cq : (n, 3) float array, ``a_i = sum_j c_ij q_ij``
    rest_scale : (n,) float array, ``sum_j c_ij |q_ij|^2``, the size of a cell's membrane term

    Examples
    --------
    >>> from srarap_cli.operators import cell_graph
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> e = RestEdges(cell_graph(V, np.array([[0, 1, 2]]), "uniform"), V)
    >>> S, s = e.covariance(V)   # rest shape: S_i = sum_j q q^T
    >>> np.allclose(S[0], [[1, 0, 0], [0, 1, 0], [0, 0, 0]])
    True
    """

    def __init__(self, graph, V):
        self.graph = graph
        self.q = V[graph.J] - V[graph.I]
        self.q_sq = np.einsum("ij,ij->i", self.q, self.q)
        n, c = graph.n, graph.c
        self.sum_cq = graph.cell_sum(c[:, None] * self.q)
        self.rest_scale = graph.cell_sum(c * self.q_sq)
        # G_b[i, j] = c_ij q_ij[b], stacked over b: (3n, n); and side by side over b: (n, 3n)
        self._stack = sp.vstack([sp.csr_matrix((c * self.q[:, b], (graph.I, graph.J)), shape=(n, n))
                                 for b in range(3)]).tocsr()
        self._side = sp.csr_matrix((np.concatenate([c * self.q[:, b] for b in range(3)]),
                                    (np.tile(graph.I, 3),
                                     np.concatenate([3 * graph.J + b for b in range(3)]))),
                                   shape=(n, 3 * n))

    def deformed(self, P):
        """Deformed edge vectors ``p_ij = p_j - p_i``: (m, 3)."""
        # np.take: about four times faster than fancy indexing for row gathers
        return np.take(P, self.graph.J, axis=0) - np.take(P, self.graph.I, axis=0)

    def covariance(self, P, p=None):
        """``S_i = sum_j c_ij p_ij q_ij^T`` (n, 3, 3) and ``s_i = sum_j c_ij(|p|^2 + |q|^2)``.

        ``p`` (from :meth:`deformed`) may be passed when the caller has it already.
        """
        g = self.graph
        GP = (self._stack @ P).reshape(3, g.n, 3)  # [b, i, a] = sum_j c q[b] P_j[a]
        S = GP.transpose(1, 2, 0) - P[:, :, None] * self.sum_cq[:, None, :]
        p = self.deformed(P) if p is None else p
        s = g.cell_sum(g.c * np.einsum("ij,ij->i", p, p)) + self.rest_scale
        return S, s

    def rotated_divergence(self, R, Rm=None):
        """``b_i = sum_j c_ij / 2 (R_i q_ij R_i~ + R_j q_ij R_j~)``: (n, 3).

        ``Rm`` (rotation matrices of ``R``) may be passed when the caller has them.
        """
        Rm = to_matrix(R) if Rm is None else Rm
        own = np.einsum("nab,nb->na", Rm, self.sum_cq)
        others = self._side @ Rm.transpose(0, 2, 1).reshape(-1, 3)  # [i, a]
        return 0.5 * (own + others)
