"""The sparse symmetric rotor system both linear methods solve, and how it is solved.

Row ``i`` (free vertex) reads ``(sigma_i M_i + tau_i I) R_i - sum_j omega_ij R_j = phi_i R_i^prev``
with symmetric edge weights ``omega``; columns of constrained vertices move to the right-hand
side. Rows are strictly block diagonally dominant (``tau_i > sum_j omega_ij``, ``M_i`` PSD), so
the matrix is symmetric positive definite, solved by conjugate gradients started from the
previous rotors (and from nothing else, so a solve depends only on its inputs: resumed
animations reproduce uninterrupted ones bit for bit); a direct factorization takes over should
CG stall. CG stops at relative residual 1e-10, or earlier at ``forcing`` times the residual of
the previous rotors (an inexact local step: its error shrinks with the outer iteration's steps).

Preconditioner: ``alpha A`` grows with the mesh while ``M_i`` does not, so the system is mostly
the graph coupling ``omega`` (a shifted Laplacian, poorly served by block-Jacobi: 50 to 300 CG
iterations). The scalar matrix ``diag(tau_i + sigma_i m_i) - omega`` with ``m_i`` the cell's rest
membrane scale is factored once per mesh; applied to the four quaternion components it brings
CG to 5 to 10 iterations on the shared meshes.
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..linalg import factor
from ..quaternion import normalize
from .constrained_rotors import constrained_rotors
from .feedback import feedback_pull
from .membrane import membrane_matrices

CG_RTOL = 1e-10
_REL_SHIFT = 1e-9


class RotorSystem:
    """Pattern and weights of one rotor system, fixed per mesh and constraint set.

    Parameters
    ----------
    edges : RestEdges
    constrained : (n,) bool array
    sigma, tau, phi : (n,) float arrays, per-row scale of ``M_i``, diagonal term, feedback
    omega : (m,) float array, symmetric edge weights aligned with ``graph.I, graph.J``
    """

    def __init__(self, edges, constrained, sigma, tau, phi, omega):
        graph = edges.graph
        self.free = np.flatnonzero(~constrained)
        self.fixed = np.flatnonzero(constrained)
        self.sigma, self.tau, self.phi = sigma, tau, phi
        W = sp.csr_matrix((omega, (graph.I, graph.J)), shape=(graph.n,) * 2)
        self._fixed_rows = W[self.fixed]
        self._free_to_fixed = W[self.free][:, self.fixed].tocsr()
        W_ff = W[self.free][:, self.free]
        self._build_pattern(W_ff)
        scalar = sp.diags(tau[self.free] + sigma[self.free] * edges.rest_scale[self.free]) - W_ff
        self._precondition = factor(scalar, symmetric=True) if self.free.size else None

    def _build_pattern(self, W_ff):
        """CSR pattern of the free system, and its data array with the constant off-diagonal
        entries in place: each build writes only the diagonal blocks into it. Gathering all
        40 entries per vertex into fresh arrays made two 240 MB arrays per iteration at 738k
        vertices, and the kernel zeroes a fresh array's pages (0.14 s for each of those here).

        Row ``4i+k`` holds, in column order, entry ``k`` of each neighbour ``j < i``, the four
        entries of ``i``'s own block, then entry ``k`` of each neighbour ``j > i``: every slot
        follows from the sorted one-ring, with no sort of the 40 entries per vertex (a
        lexsort took 5 s at 738k vertices)."""
        W = sp.csr_matrix(W_ff)
        W.sort_indices()
        nf, k = W.shape[0], np.arange(4)
        deg = np.diff(W.indptr)
        row = np.repeat(np.arange(nf), deg)
        after = W.indices > row
        before = np.bincount(row, weights=~after, minlength=nf).astype(np.int64)
        length = deg + 4
        start = 4 * (W.indptr[:-1].astype(np.int64) + 4 * np.arange(nf))
        rank = np.arange(W.nnz) - W.indptr[row] + 4 * after
        off = (start[row] + rank)[:, None] + k * length[row][:, None]
        diag = (start + before)[:, None, None] + k[:, None] * length[:, None, None] + k
        total = 4 * W.nnz + 16 * nf
        # 32-bit indices: scipy would copy 64-bit ones down to them on every build
        index = np.int32 if total < np.iinfo(np.int32).max else np.int64
        self._indices = np.empty(total, index)
        self._indices[off] = 4 * W.indices[:, None] + k
        self._indices[diag] = np.broadcast_to(4 * np.arange(nf)[:, None, None] + k, diag.shape)
        self._indptr = np.append(start[:, None] + k * length[:, None], total).astype(index)
        self._data = np.empty(total)
        self._data[off] = -W.data[:, None]
        self._diagonal_slots = diag.ravel()

    def diagonal_blocks(self, S, s):
        """``sigma_i M_i + tau_i I`` (plus a tiny scale-relative shift): (n, 4, 4)."""
        M = membrane_matrices(S, s)
        shift = _REL_SHIFT * max(float(self.tau.max(initial=0)), float(np.abs(M).max(initial=0)))
        return self.sigma[:, None, None] * M + (self.tau + shift)[:, None, None] * np.eye(4)

    def free_system(self, D, R_prev, R_fixed):
        """Sparse matrix and right-hand side (flattened, 4 per free vertex)."""
        nf = self.free.size
        # the matrix shares self._data: valid until the next build (the solve uses it at once)
        self._data[self._diagonal_slots] = D[self.free].reshape(-1)
        A = sp.csr_matrix((self._data, self._indices, self._indptr), shape=(4 * nf, 4 * nf))
        b = feedback_pull(self.phi[self.free], R_prev[self.free]) + self._free_to_fixed @ R_fixed
        return A, b.ravel()

    def step(self, S, s, R_prev, forcing=0.0):
        """New unit rotors: constrained rotors from their own rows (section 6.2), then one
        solve for all free rotors, to ``forcing`` times the previous rotors' residual."""
        D = self.diagonal_blocks(S, s)
        R = R_prev.copy()
        if self.fixed.size:
            R[self.fixed] = constrained_rotors(
                D[self.fixed], self._fixed_rows @ R_prev,
                feedback_pull(self.phi[self.fixed], R_prev[self.fixed]), R_prev[self.fixed])
        if self.free.size:
            A, b = self.free_system(D, R_prev, R[self.fixed])
            sol = self._solve(A, b, R_prev[self.free].ravel(), forcing)
            R[self.free] = normalize(sol.reshape(-1, 4), R_prev[self.free])
        return R

    def _solve(self, A, b, x0, forcing):
        solve = self._precondition
        # with its dtype given, LinearOperator does not try a preconditioner solve to guess it
        precond = spla.LinearOperator(
            A.shape, matvec=lambda v: solve(np.asfortranarray(v.reshape(-1, 4))).ravel(),
            dtype=float)
        # CG for the correction from x0, whose right-hand side is x0's residual: relative to
        # it, the forcing is CG's own rtol, and CG needs no second product for its residual
        correction, info = spla.cg(A, b - A @ x0, rtol=forcing,
                                   atol=CG_RTOL * float(np.linalg.norm(b)), M=precond,
                                   maxiter=max(200, 4 * A.shape[0]))
        if info != 0:
            return factor(A, symmetric=True)(b)
        return x0 + correction
