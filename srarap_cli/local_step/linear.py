"""The paper's local step: all rotors from ONE sparse 4n x 4n linear solve (sections 6.1-6.3).

Row ``i`` of the system (as in the reference implementation) is

``(M_i + alpha A I + delta I) R_i - alpha A / (deg_i + eps) sum_j R_j = alpha A eps / (deg_i + eps) R_i^prev``

with ``eps`` the feedback strength. Constrained (handle) vertices get their rotor first from
their own 4x4 version of that row with the neighbours' previous rotors (section 6.2); their
columns then move to the right-hand side. Every solution rotor is normalized.
``delta`` is a tiny scale-relative diagonal shift (the reference adds an absolute 1e-6,
which is not scale invariant).

The reference calls this system non-symmetric and uses sparse LU. Multiplying row ``i`` by
``deg_i + eps`` turns every off-diagonal block into ``-alpha A I``: the same system, same
solution, now symmetric and strictly block diagonally dominant, hence positive definite. It
is solved by conjugate gradients with a block-Jacobi preconditioner, warm-started from the
previous rotors, to a relative residual of 1e-10 (an order of magnitude faster than LU here);
a direct factorization takes over should CG ever stall.
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..global_step import factor
from ..quaternion import normalize
from .membrane import membrane_matrices

_REL_SHIFT = 1e-9
CG_RTOL = 1e-10


class LinearRotorStep:
    """Precomputed pattern of the rotor system for one mesh and constraint set.

    Parameters
    ----------
    graph : CellGraph
    constrained : (n,) bool array
    alpha_area : float, ``alpha * A``
    feedback : float, ``eps >= 0``
    """

    def __init__(self, graph, constrained, alpha_area, feedback):
        self.graph = graph
        self.free = np.flatnonzero(~constrained)
        self.fixed = np.flatnonzero(constrained)
        self.alpha_area = alpha_area
        self.feedback = feedback
        self.cg_iterations = 0
        self._last = None
        denom = (graph.degree + feedback).astype(float)
        self._row_scale = denom[self.free]
        adjacency = sp.csr_matrix((np.full(graph.I.size, alpha_area), (graph.I, graph.J)),
                                  shape=(graph.n,) * 2)
        fixed_denom = np.where(denom[self.fixed] > 0, denom[self.fixed], 1.0)
        self._fixed_neighbours = sp.diags(1.0 / fixed_denom) @ adjacency[self.fixed]
        self._fixed_self = np.where(denom[self.fixed] > 0,
                                    alpha_area * feedback / fixed_denom, 0.0)
        self._free_to_fixed = adjacency[self.free][:, self.fixed].tocsr()
        self._build_pattern(adjacency[self.free][:, self.free].tocoo())

    def _build_pattern(self, free_adj):
        """Fix the sparse layout of the (symmetric) free system; per step only values change."""
        nf = self.free.size
        k = np.arange(4)
        off_r = (4 * free_adj.row[:, None] + k).ravel()
        off_c = (4 * free_adj.col[:, None] + k).ravel()
        self._off_vals = -np.repeat(free_adj.data, 4)
        blk = np.arange(nf)[:, None, None] * 4
        diag_r = np.broadcast_to(blk + k[:, None], (nf, 4, 4)).ravel()
        diag_c = np.broadcast_to(blk + k[None, :], (nf, 4, 4)).ravel()
        rows = np.concatenate([off_r, diag_r])
        cols = np.concatenate([off_c, diag_c])
        self._order = np.lexsort((cols, rows))
        self._indices = cols[self._order]
        self._indptr = np.searchsorted(rows[self._order], np.arange(4 * nf + 1))

    def _shifted(self, M):
        shift = self.alpha_area + _REL_SHIFT * max(self.alpha_area, float(np.abs(M).max(initial=0)))
        return M + shift * np.eye(4)

    def free_system(self, M, R_prev, R_fixed):
        """The row-scaled symmetric system ``(A, b)`` for the free rotors, flattened 4 per vertex."""
        nf = self.free.size
        diag = self._row_scale[:, None, None] * M[self.free]
        data = np.concatenate([self._off_vals, diag.ravel()])[self._order]
        A = sp.csr_matrix((data, self._indices, self._indptr), shape=(4 * nf, 4 * nf))
        b = self.alpha_area * self.feedback * R_prev[self.free] + self._free_to_fixed @ R_fixed
        return A, b.ravel(), diag

    def __call__(self, S, s, R_prev):
        """New unit rotors (n, 4) from cell covariances ``S, s`` and the previous rotors."""
        M = self._shifted(membrane_matrices(S, s))
        R = R_prev.copy()
        if self.fixed.size:
            rhs = self._fixed_neighbours @ R_prev + self._fixed_self[:, None] * R_prev[self.fixed]
            R[self.fixed] = normalize(np.linalg.solve(M[self.fixed], rhs[..., None])[..., 0],
                                      R_prev[self.fixed])
        if self.free.size:
            A, b, diag = self.free_system(M, R_prev, R[self.fixed])
            sol = self._solve(A, b, diag, self._warm_start(R_prev))
            R[self.free] = normalize(sol.reshape(-1, 4), R_prev[self.free])
            self._last = (sol, R[self.free])
        return R

    def _warm_start(self, R_prev):
        """The previous raw (unnormalized) solution when it belongs to these rotors.

        Raw solutions are not unit length; starting CG from the normalized rotors would waste
        its first iterations on recovering their scale.
        """
        if self._last is not None and np.array_equal(self._last[1], R_prev[self.free]):
            return self._last[0]
        return R_prev[self.free].ravel()

    def _solve(self, A, b, diag, x0):
        nf = diag.shape[0]
        precond = sp.bsr_matrix((np.linalg.inv(diag), np.arange(nf), np.arange(nf + 1)),
                                shape=A.shape)
        count = [0]

        def tick(_):
            count[0] += 1

        x, info = spla.cg(A, b, x0=x0, rtol=CG_RTOL, atol=0.0, M=precond,
                          maxiter=max(200, 4 * A.shape[0]), callback=tick)
        self.cg_iterations = count[0]
        if info != 0:
            x = factor(A, symmetric=True)(b)
        return x
