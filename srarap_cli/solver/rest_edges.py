"""Rest-shape edge data as sparse operators, so per-iteration sums are sparse products."""

import numpy as np
import scipy.sparse as sp

from .operators import CellGraph
from .quaternion import to_matrix


class RestEdges:
    """Rest edges ``q_ij = q_j - q_i`` of a cell graph, precomputed for the loop.

    Attributes
    ----------
    q : (m, 3) float array; q_sq : (m,) float array (computed when read)
    sum_cq : (n, 3) float array, ``a_i = sum_j c_ij q_ij``
    rest_scale : (n,) float array, ``sum_j c_ij |q_ij|^2``, the size of a cell's membrane term

    Examples
    --------
    >>> from srarap_cli.solver.operators import cell_graph
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> e = RestEdges(cell_graph(V, np.array([[0, 1, 2]]), "uniform"), V)
    >>> S, s = e.covariance(V)   # rest shape: S_i = sum_j q q^T
    >>> np.allclose(S[0], [[1, 0, 0], [0, 1, 0], [0, 0, 0]])
    True
    """

    def __init__(self, graph: CellGraph, V: np.ndarray) -> None:
        self.graph = graph
        self._V = V
        q = self.q
        c, n = graph.c, graph.n
        self.sum_cq = graph.cell_sum(c[:, None] * q)
        self.rest_scale = graph.cell_sum(c * np.einsum("ij,ij->i", q, q))
        # S_i[a, b] = sum_j c_ij q_ij[b] (P_j - P_i)[a]: rows b * n + i, the -P_i part on the
        # diagonal, so one sparse product gives every covariance
        rows = np.concatenate([graph.I, np.arange(n)])
        cols = np.concatenate([graph.J, np.arange(n)])
        self._covariance = sp.vstack([
            sp.csr_matrix((np.concatenate([c * q[:, b], -self.sum_cq[:, b]]), (rows, cols)),
                          shape=(n, n)) for b in range(3)]).tocsr()
        self._half: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._rest_total = float(self.rest_scale.sum())

    @property
    def q(self) -> np.ndarray:
        """Rest edge vectors ``q_ij`` (m, 3), gathered when asked for: only energy checks
        and setup need them, and at 738k vertices they would hold 0.1 GB."""
        return self.deformed(self._V)

    @property
    def rest_positions(self) -> np.ndarray:
        """The rest positions (n, 3) the edges were taken from."""
        return self._V

    @property
    def rest_moment(self) -> np.ndarray:
        """``T_i = sum_j c_ij q_ij q_ij^T``: (n, 3, 3), the covariance of the rest shape."""
        return self.cross(self._V)

    @property
    def q_sq(self) -> np.ndarray:
        """``|q_ij|^2``: (m,)."""
        q = self.q
        return np.einsum("ij,ij->i", q, q)

    def deformed(self, P: np.ndarray) -> np.ndarray:
        """Deformed edge vectors ``p_ij = p_j - p_i``: (m, 3)."""
        # np.take: about four times faster than fancy indexing for row gathers
        return np.take(P, self.graph.J, axis=0) - np.take(P, self.graph.I, axis=0)

    def covariance(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``S_i = sum_j c_ij p_ij q_ij^T`` (n, 3, 3) and ``s_i = sum_j c_ij(|p|^2 + |q|^2)``."""
        return self.cross(P), self.stretch(P)

    def cross(self, P: np.ndarray) -> np.ndarray:
        """``S_i = sum_j c_ij p_ij q_ij^T``: (n, 3, 3), from one sparse product."""
        # contiguous: einsums over a transposed view ran twice as slow downstream
        return np.ascontiguousarray(
            (self._covariance @ P).reshape(3, self.graph.n, 3).transpose(1, 2, 0))

    def stretch(self, P: np.ndarray) -> np.ndarray:
        """``s_i = sum_j c_ij(|p_ij|^2 + |q_ij|^2)``: (n,)."""
        g = self.graph
        s = self.rest_scale.copy()
        for e in g.edge_blocks():
            d = np.take(P, g.J[e], axis=0) - np.take(P, g.I[e], axis=0)
            s += g.cell_sum(g.c[e] * np.einsum("ij,ij->i", d, d), e)
        return s

    def stretch_total(self, P: np.ndarray) -> float:
        """``sum_i s_i`` (float), over each undirected edge once: half the work of
        :meth:`stretch` for callers that need only the sum."""
        if self._half is None:
            # each undirected edge once (weights are symmetric); made on first use, as the
            # methods that need per-cell stretch never call this (53 MB at 738k vertices)
            g = self.graph
            half = g.I < g.J
            self._half = g.I[half], g.J[half], g.c[half]
        I, J, c = self._half
        total = 0.0
        for e in self.graph.edge_blocks(I.size):
            d = np.take(P, J[e], axis=0) - np.take(P, I[e], axis=0)
            total += float(c[e] @ np.einsum("ij,ij->i", d, d))
        return 2.0 * total + self._rest_total

    def rotated_divergence(self, R: np.ndarray, Rm: np.ndarray | None = None) -> np.ndarray:
        """``b_i = sum_j c_ij / 2 (R_i q_ij R_i~ + R_j q_ij R_j~)``: (n, 3).

        ``Rm`` (rotation matrices of ``R``) may be passed when the caller has them.
        """
        Rm = to_matrix(R) if Rm is None else Rm
        # c_ij is symmetric and q_ij = -q_ji, so the covariance operator's transpose holds
        # -c_ij q_ij[b] at (i, b n + j) and -sum_j c_ij q_ij[b] at (i, b n + i): minus twice
        # this operator, on the columns R_j[:, b] stacked by b (no second 0.2 GB matrix at
        # 738k vertices, and as fast)
        return -0.5 * (self._covariance.T @ Rm.transpose(2, 0, 1).reshape(-1, 3))
