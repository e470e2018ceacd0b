"""Global step: positions from rotors by a Poisson solve, factored once (paper section 5)."""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


class SingularSystemError(RuntimeError):
    """A factorization met a singular matrix (for example a part with no constraint)."""


def factor(A, symmetric):
    """LU-factor a sparse square matrix; returns a callable ``solve(b)``.

    A symmetric matrix gets a symmetric fill-reducing ordering, which roughly halves the
    fill of SuperLU's default column ordering on mesh Laplacians.
    """
    try:
        lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A" if symmetric else "COLAMD")
    except RuntimeError as exc:  # SuperLU reports an exactly singular matrix this way
        raise SingularSystemError(str(exc)) from exc
    return lu.solve


class PoissonSolver:
    """Solve ``K P = -b`` for the free vertices with constrained vertices eliminated.

    ``K`` is the graph's positive semi-definite Laplacian; removing the constrained rows and
    columns leaves a symmetric positive definite matrix (each part of the mesh holds at least
    one constrained vertex), factored here once and reused for every right-hand side.

    Parameters
    ----------
    graph : CellGraph
    constrained : (n,) bool array
    """

    def __init__(self, graph, constrained):
        self.graph = graph
        self.free = np.flatnonzero(~constrained)
        self.fixed = np.flatnonzero(constrained)
        K = graph.laplacian
        self._K_fc = K[self.free][:, self.fixed].tocsr()
        self._solve = factor(K[self.free][:, self.free], symmetric=True) if self.free.size else None

    def solve(self, b, targets):
        """Positions with ``P[fixed] = targets`` minimizing the membrane energy for ``b``.

        Parameters
        ----------
        b : (n, 3) float array, from :meth:`RestEdges.rotated_divergence`
        targets : (k, 3) float array, positions of the constrained vertices in index order
        """
        P = np.empty((self.graph.n, 3))
        P[self.fixed] = targets
        if self._solve is not None:
            P[self.free] = self._solve(-b[self.free] - self._K_fc @ targets)
        return P
