"""Global step: positions from rotors by a Poisson solve, factored once (paper section 5)."""
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .linalg import factor
from .operators import CellGraph


class PoissonSolver:
    """Solve ``K P = -b`` for the free vertices with the constrained vertices' positions given.

    ``K`` is the graph's positive semi-definite Laplacian. The factored matrix is ``K`` with
    the constrained rows and columns replaced by identity ones: symmetric positive definite
    (each part of the mesh holds at least one constrained vertex), the same fill as the free
    block alone, and a solve then needs no gather or scatter of the free rows.

    Parameters
    ----------
    graph : CellGraph
    constrained : (n,) bool array
    """

    def __init__(self, graph: CellGraph, constrained: np.ndarray) -> None:
        self.fixed = np.flatnonzero(constrained)
        K = graph.laplacian
        free = ~constrained
        inside = free[graph.I] & free[graph.J]
        # every free-free mesh edge stays in the pattern, a clamped weight of 0 included: the
        # rotor preconditioner has the same one, and one fill-reducing ordering serves both
        ids = np.arange(graph.n)
        A = sp.csr_matrix((np.r_[-graph.c[inside], np.where(free, K.diagonal(), 1.0)],
                           (np.r_[graph.I[inside], ids], np.r_[graph.J[inside], ids])),
                          shape=K.shape)
        self._solve = factor(A, symmetric=True, order=graph.fill_order)
        self._to_fixed = K[:, self.fixed].tocsr()
        self._free_column = free.astype(float)[:, None]

    def bind(self, targets: np.ndarray) -> Callable:
        """The solve for one set of constrained positions, reused for many right-hand sides.

        Parameters
        ----------
        targets : (k, 3) float array, positions of the constrained vertices in index order

        Returns
        -------
        callable: ``b`` (n, 3) (from :meth:`RestEdges.rotated_divergence`) -> positions (n, 3)
        with ``P[fixed] = targets`` minimizing the membrane energy for ``b``
        """
        base = -(self._to_fixed @ targets) * self._free_column
        base[self.fixed] = targets
        return lambda b: self._solve(base - b * self._free_column)
