"""How a solved shape answers a small move of its handles: the first-order change of the
minimum (implicit function theorem), for warm starts.

A warm start that only moves the handles (and spreads their rotation) leaves an error of the
order of the move: after every target was scaled by 1.01, the sample Spot's warm start began
2e-3 above the minimum and the iteration took 19 of a cold solve's 26 iterations to remove
it, at the rate of a cold run's tail. Differentiating the minimum's condition ``grad E = 0``
along the move gives the change to first order, ``Q dx = -Q_xt dt`` with ``Q`` half the
energy's Hessian (:mod:`.hessian`); the left error is of the order of the move squared.

The positions' block of ``Q`` is the Poisson matrix, factored already, so the rotors'
increments solve the Schur complement ``S = Q_ww - Q_wu Q_uu^-1 Q_uw`` by conjugate
gradients, one Poisson solve per product. Its preconditioner is ``Q_ww`` as it is at a
converged state made isotropic and state-free: the bending graph Laplacian plus two thirds
of each cell's rest scale ``sum_j c_ij |q_ij|^2`` (the membrane block's trace / 3 when
``r = 0``), one scalar matrix factored once per solver. Measured at the converged states of
the benchmark cases (sample bar, cylinder, Max bust, Spot): 4 to 5 iterations to a relative
residual of 1e-2, against 20 to 100 unpreconditioned; the full ``Q_ww`` (3x3 blocks,
factored per state, 9 times the cost) needed as many.
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .hessian import energy_hessian
from .linalg import factor
from .local_step.linear_sym import symmetric_weights
from .precomputed import Precomputed

#: relative residual of the rotors' system: the prediction's error is then about 1% of the
#: first-order change, far below the second-order error it leaves anyway
RTOL = 1e-2
#: conjugate-gradient iterations at most (a state far from converged may give an indefinite
#: system; the warm start keeps the prediction only if it lowers the energy)
MAX_ITERATIONS = 40


class LinearResponse:
    """First-order change of a solved state when the held vertices move; built once per
    :class:`~srarap_cli.solver.deformer.Deformer` (the preconditioner's factor), used for
    any state.

    Parameters
    ----------
    deformer : Deformer
    """

    def __init__(self, deformer: Precomputed) -> None:
        self.deformer = deformer
        graph = deformer.graph
        # the bending pairs as the total-energy rotor system couples them (1/deg_i + 1/deg_j)
        beta = deformer.bending_weight / 4.0 * symmetric_weights(graph)
        W = sp.csr_matrix((beta, (graph.I, graph.J)), shape=(graph.n,) * 2)
        diagonal = graph.cell_sum(beta) + 2.0 / 3.0 * deformer.edges.rest_scale
        # a vertex in no triangle has no energy: any value keeps its row solvable
        diagonal[diagonal <= 0] = 1.0
        M = (sp.diags(diagonal) - W).tocsr()
        self._precondition = factor(M, symmetric=True, order=graph.fill_order,
                                    approximate=True)

    def rotations(self, P: np.ndarray, R: np.ndarray, moved: np.ndarray) -> np.ndarray | None:
        """Rotor increments ``w`` (n, 3), rotation vectors turning each rotor to
        ``exp(w / 2) R``, that follow the held vertices' move ``moved`` to first order from
        the state ``(P, R)``; None when the system gave no finite answer.

        Parameters
        ----------
        P : (n, 3) float array; R : (n, 4) float array, unit quaternions
        moved : (j, 3) float array, the move of each vertex of ``deformer.fixed``
        """
        d = self.deformer
        n = len(P)
        H = energy_hessian(d.graph, d.edges, P, R, d.bending_weight)
        poisson = d.poisson
        # the positions' first-order change for unchanged rotors: harmonic, exact at the
        # held vertices; bind(0) solves with the held vertices kept where they are
        u = poisson.bind(moved)(np.zeros((n, 3)))
        held_still = poisson.bind(np.zeros_like(moved))

        def schur(v):
            v = v.reshape(n, 3)
            # Q_uu^-1 y = K^-1 y / 2 on the free rows; bind(0) returns -K^-1 y
            z = -0.5 * held_still(H.coupling_t(v))
            return (H.rotations(v) - H.coupling(z)).ravel()

        shape = (3 * n, 3 * n)
        w, _ = spla.cg(spla.LinearOperator(shape, matvec=schur, dtype=float),
                       -H.coupling(u).ravel(), rtol=RTOL, maxiter=MAX_ITERATIONS,
                       M=spla.LinearOperator(shape, dtype=float, matvec=lambda v: (
                           self._precondition(v.reshape(n, 3)).ravel())))
        return w.reshape(n, 3) if np.isfinite(w).all() else None
