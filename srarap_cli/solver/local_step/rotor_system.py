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
CG to 5 to 10 iterations on the shared meshes. It is factored in single precision (an
approximate inverse is all CG asks of it): the same CG iterations, and its triangular solves,
one per CG iteration, read half the bytes (four columns at 50k vertices: 18 -> 11 ms).

The membrane blocks grow with the deformed edges: a handle moved 100 to 10^6 bounding-box
diagonals away makes them 10^4 to 10^12 times their rest size, and a preconditioner built on the
rest scale then needs 120 to 300 CG iterations (measured on a 4,850-vertex tube), so the cost of
an iteration grew with the distance. Each cell's scale is therefore followed in powers of 4: a
cell whose mean diagonal is 8 or more times the rest one is preconditioned at ``4^k`` times it,
and the scalar matrix is factored again when those powers change (a pure function of the
current blocks, so solves stay reproducible). Ordinary deformations never reach the factor 8
and keep the rest factorization; far handles take 4 to 6 CG iterations.
"""
from functools import partial

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csr_matrix

from ...runtime.parallel import blocks, fill, map_blocks, ordered_sum
from ..linalg import factor
from ..operators import row_views
from ..quaternion import normalize
from ..rest_edges import RestEdges
from .block_cg import conjugate_gradients
from .constrained_rotors import constrained_rotors
from .feedback import feedback_pull
from .membrane import membrane_matrices

CG_RTOL = 1e-10
# CG iterations at most before the direct fallback: the preconditioned system takes 5 to 30
CG_MAXITER = 500
_DIAG = np.arange(4)
_REL_SHIFT = 1e-9


class RotorSystem:
    """Weights and preconditioner of one rotor system, fixed per mesh and set of held rotors.

    Parameters
    ----------
    edges : RestEdges
    constrained : (n,) bool array, vertices whose rotors come from their own rows (section 6.2)
    sigma, tau, phi : (n,) float arrays, per-row scale of ``M_i``, diagonal term, feedback
    omega : (m,) float array, symmetric edge weights aligned with ``graph.I, graph.J``
    """

    def __init__(self, edges: RestEdges, constrained: np.ndarray, sigma: np.ndarray, tau: np.ndarray,
                 phi: np.ndarray, omega: np.ndarray) -> None:
        graph = edges.graph
        self.free = np.flatnonzero(~constrained)
        self.fixed = np.flatnonzero(constrained)
        self.sigma, self.tau, self.phi = sigma, tau, phi
        W = sp.csr_matrix((omega, (graph.I, graph.J)), shape=(graph.n,) * 2)
        self._fixed_rows = W[self.fixed]
        self._free_to_fixed = W[self.free][:, self.fixed].tocsr()
        self._coupling = _int32(W[self.free][:, self.free].tocsr())
        self._coupling_blocks = row_views(self._coupling)
        self._order = partial(graph.fill_order, self.free)
        self._rest_diagonal = tau[self.free] + sigma[self.free] * edges.rest_scale[self.free]
        self._powers = np.zeros(self.free.size, dtype=np.int8)
        self._precondition = self._factor_scalar(self._powers) if self.free.size else None

    def _factor_scalar(self, powers):
        scalar = sp.diags(self._rest_diagonal * 4.0 ** powers) - self._coupling
        return factor(scalar, symmetric=True, order=self._order, approximate=True)

    def _preconditioner(self, D):
        """The scalar preconditioner for the free blocks ``D``: the one of the rest scale, or
        one at each cell's current scale in powers of 4 (see the module's docstring)."""
        ratio = np.einsum("nii->n", D) / (4.0 * self._rest_diagonal)
        powers = np.floor(np.log(np.maximum(ratio, 2.0) / 2.0) / np.log(4.0))
        powers = np.minimum(powers, 120).astype(np.int8)
        if not np.array_equal(powers, self._powers):
            self._precondition, self._powers = self._factor_scalar(powers), powers
        return self._precondition

    def diagonal_blocks(self, S: np.ndarray, s: np.ndarray) -> np.ndarray:
        """``sigma_i M_i + tau_i I`` (plus a tiny scale-relative shift): (n, 4, 4)."""
        D = np.empty((len(s), 4, 4))
        size = max(map_blocks(partial(_membrane_block, S, s, D), blocks(len(s))), default=0.0)
        shift = _REL_SHIFT * max(float(self.tau.max(initial=0)), size)
        map_blocks(partial(_scale_block, D, self.sigma, self.tau, shift), blocks(len(s)))
        return D

    def free_system(self, D: np.ndarray, R_prev: np.ndarray, R_fixed: np.ndarray
                    ) -> tuple["FreeRotorMatrix", np.ndarray]:
        """The free rotors' matrix (a :class:`FreeRotorMatrix`) and right-hand side
        (flattened, 4 per free vertex)."""
        free = fill(lambda ids: np.take(D, ids, axis=0), np.empty((self.free.size, 4, 4)),
                       self.free)
        A = FreeRotorMatrix(free, self._coupling, self._coupling_blocks)
        self._preconditioner(A.D)
        b = feedback_pull(self.phi[self.free], R_prev[self.free]) + self._free_to_fixed @ R_fixed
        return A, b.ravel()

    def step(self, S: np.ndarray, s: np.ndarray, R_prev: np.ndarray, forcing: float = 0.0) -> np.ndarray:
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
            del D  # A holds a copy of the free blocks
            sol = self._solve(A, b, R_prev[self.free].ravel(), forcing)
            R[self.free] = normalize(sol.reshape(-1, 4), R_prev[self.free])
        return R

    def _solve(self, A, b, x0, forcing):
        solve = self._precondition
        assert solve is not None  # there are free rotors to solve for
        # CG for the correction from x0, whose right-hand side is x0's residual: relative to
        # it, the forcing is CG's own rtol, and CG needs no second product for its residual
        residual = np.empty_like(b)
        A.product(x0, residual)
        residual -= b
        residual *= -1.0
        correction, info = conjugate_gradients(
            A.product, lambda r: solve(r.reshape(-1, 4)).ravel(), residual, rtol=forcing,
            atol=CG_RTOL * float(np.linalg.norm(b)), maxiter=CG_MAXITER)
        if info != 0:
            return factor(A.tocsr(), symmetric=True)(b)
        return x0 + correction


class FreeRotorMatrix(spla.LinearOperator):
    """The free rotors' matrix ``blockdiag(D_i) - kron(W, I_4)``, applied without forming it.

    Its off-diagonal blocks are multiples of the identity, so a product is one scalar sparse
    product on the four quaternion columns plus the 4x4 diagonal blocks: as fast as the
    assembled CSR matrix (39 ms at 738k vertices either way), without its 29.5M entries
    (0.45 GB with their indices and the slots the per-step diagonal went to).

    Parameters
    ----------
    D : (nf, 4, 4) float array, diagonal blocks
    W : (nf, nf) sparse matrix, symmetric coupling weights
    blocks : list of (rows, W's rows), optional: :func:`row_views` of ``W`` (a solver that
        makes many matrices of one ``W`` makes them once)
    """

    def __init__(self, D: np.ndarray, W: csr_matrix,
                 blocks: list[tuple[slice, csr_matrix]] | None = None) -> None:
        super().__init__(dtype=float, shape=(4 * D.shape[0],) * 2)
        self.D, self.W = D, W if sp.isspmatrix_csr(W) else sp.csr_matrix(W)
        self._blocks = row_views(self.W) if blocks is None else blocks

    def _matvec(self, v):
        out = np.empty(v.shape[0])
        self.product(np.ascontiguousarray(v, dtype=float).ravel(), out)
        return out

    def product(self, p: np.ndarray, q: np.ndarray) -> float:
        """``q = A p`` (flat (4 nf,) arrays) by blocks of rows; returns ``p . q`` (per-block
        sums added in block order): conjugate gradients' product and the dot it feeds, in
        one pass."""
        return ordered_sum(partial(_product_block, self.D, p.reshape(-1, 4), q.reshape(-1, 4)),
                           self._blocks)

    def tocsr(self) -> csr_matrix:
        """The assembled sparse matrix (for the direct fallback)."""
        nf = self.D.shape[0]
        blocks = sp.bsr_matrix((self.D, np.arange(nf), np.arange(nf + 1)), shape=self.shape)
        return (blocks - sp.kron(self.W, sp.identity(4))).tocsr()


def _int32(A):
    """``A`` with 32-bit indices when they fit: scipy copies 64-bit ones on every product."""
    if A.nnz < np.iinfo(np.int32).max:
        A.indices, A.indptr = A.indices.astype(np.int32), A.indptr.astype(np.int32)
    return A


def _product_block(D, X, out, item):
    """``out[rows] = (A X)[rows]`` for a block of rows (each whole: the same values at any
    thread count); returns ``X[rows] . out[rows]``."""
    rows, W = item
    part = np.einsum("nij,nj->ni", D[rows], X[rows])
    part -= W @ X
    out[rows] = part
    return float(np.einsum("ij,ij->", X[rows], part))


def _membrane_block(S, s, D, rows):
    """``D[rows]``, a block's membrane matrices; returns their largest entry (no ``|D|``
    temporary)."""
    D[rows] = membrane_matrices(S[rows], s[rows])
    return max(float(D[rows].max(initial=0)), -float(D[rows].min(initial=0)))


def _scale_block(D, sigma, tau, shift, rows):
    """``D[rows]`` scaled by ``sigma`` and shifted by ``tau + shift``, in place: each
    (n, 4, 4) temporary is 94 MB at 738k vertices."""
    D[rows] *= sigma[rows, None, None]
    D[rows, _DIAG, _DIAG] += (tau[rows] + shift)[:, None]
