"""Rest-shape edge data as sparse operators, so per-iteration sums are sparse products."""

from functools import partial

import numpy as np
import scipy.sparse as sp

from ..runtime.parallel import map_blocks, ordered_sum
from .operators import CellGraph, row_views
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
        # S_i[a, b] = sum_j c_ij q_ij[b] (P_j - P_i)[a]: row i of matrix b holds c_ij q_ij[b]
        # at j and the -P_i part on the diagonal (columns in order), so one sparse product per
        # b gives every covariance. The three matrices share one index array, and each block
        # of rows is a view of them: threads multiply blocks.
        rows = np.concatenate([graph.I, np.arange(n)])
        cols = np.concatenate([graph.J, np.arange(n)])
        order = np.lexsort((cols, rows))
        indices = _int32(cols[order])
        indptr = _int32(np.concatenate([[0], np.cumsum(graph.degree + 1)]))
        matrices = [sp.csr_matrix((np.concatenate([c * q[:, b], -self.sum_cq[:, b]])[order],
                                   indices, indptr), shape=(n, n), copy=False)
                    for b in range(3)]
        views = [row_views(matrix) for matrix in matrices]
        self._blocks = views[0].carrying((rows, [v[k][1] for v in views])
                                         for k, (rows, _) in enumerate(views[0]))
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
        """``S_i = sum_j c_ij p_ij q_ij^T``: (n, 3, 3), from sparse products by blocks of rows."""
        S = np.empty((self.graph.n, 3, 3))
        map_blocks(partial(_cross_block, np.asarray(P, dtype=float), S), self._blocks)
        return S

    def stretch(self, P: np.ndarray) -> np.ndarray:
        """``s_i = sum_j c_ij(|p_ij|^2 + |q_ij|^2)``: (n,)."""
        g = self.graph
        s = self.rest_scale.copy()
        # each block's sums added in block order: a cell whose edges two blocks share gets
        # its two parts in the same order at every thread count
        for first, part in map_blocks(partial(_stretch_block, g, P), g.edge_blocks()):
            s[first:first + part.size] += part
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

        total = ordered_sum(partial(_weighted_lengths, P, I, J, c), self.graph.edge_blocks(I.size))
        return 2.0 * total + self._rest_total

    def rotated_divergence(self, R: np.ndarray, Rm: np.ndarray | None = None) -> np.ndarray:
        """``b_i = sum_j c_ij / 2 (R_i q_ij R_i~ + R_j q_ij R_j~)``: (n, 3).

        ``Rm`` (rotation matrices of ``R``) may be passed when the caller has them.
        """
        Rm = to_matrix(R) if Rm is None else Rm
        # c_ij is symmetric and q_ij = -q_ji: row i of the transposed covariance operator is
        # minus row i of the covariance matrices with the diagonal's sign flipped, so the same
        # matrices give b (no second 0.2 GB operator at 738k vertices), a block of rows each
        columns = np.ascontiguousarray(Rm.transpose(2, 0, 1))  # (3, n, 3): columns by b
        out = np.empty((self.graph.n, 3))
        map_blocks(partial(_divergence_block, columns, self.sum_cq, out), self._blocks)
        return out


def _cross_block(P, S, item):
    """``S[rows]`` from a block's rows of the covariance operators."""
    rows, matrices = item
    for b, matrix in enumerate(matrices):
        S[rows, :, b] = matrix @ P


def _stretch_block(g, P, e):
    """A block ``e`` of edges' weighted squared lengths summed per cell: (its first cell,
    the sums from there)."""
    I = g.I[e]
    d = np.take(P, g.J[e], axis=0) - np.take(P, I, axis=0)
    first = int(I[0])
    return first, np.bincount(I - first, weights=g.c[e] * np.einsum("ij,ij->i", d, d))


def _divergence_block(columns, sum_cq, out, item):
    """``out[rows]`` of the rotated divergence from a block's rows of the operators."""
    rows, matrices = item
    acc = np.zeros((rows.stop - rows.start, 3))
    for b, matrix in enumerate(matrices):
        acc += matrix @ columns[b]
        acc += (2.0 * sum_cq[rows, b])[:, None] * columns[b, rows]
    out[rows] = 0.5 * acc


def _weighted_lengths(P, I, J, c, e):
    """``sum c_ij |p_j - p_i|^2`` over a block ``e`` of the edges ``(I, J)``."""
    d = np.take(P, J[e], axis=0) - np.take(P, I[e], axis=0)
    return float(c[e] @ np.einsum("ij,ij->i", d, d))


def _int32(a: np.ndarray) -> np.ndarray:
    """``a`` as 32-bit indices when they fit: scipy copies 64-bit ones on every product."""
    return a.astype(np.int32) if a.size == 0 or a.max() < np.iinfo(np.int32).max else a
