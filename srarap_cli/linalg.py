"""Sparse factorizations shared by the Poisson solve and the rotor systems' preconditioner."""
import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import SingularSystemError

# Above this size SuperLU's minimum-degree ordering is what takes the time (on the 738k-vertex
# Laplacian it had not finished after 12 minutes), while libigl's sparse Cholesky (Eigen, AMD
# ordering) factored it in 31 s and 1.4 GB; on 46k vertices the two are equal (0.4 s factor,
# 26-28 ms for a 4-column solve).
LARGE = 200_000


def factor(A, symmetric):
    """LU-factor a sparse square matrix; returns a callable ``solve(b)``.

    A symmetric matrix gets a symmetric fill-reducing ordering, which roughly halves the
    fill of SuperLU's default column ordering on mesh Laplacians, and SuperLU's symmetric
    mode (diagonal pivots preferred): with the same fill, its triangular solves ran 1.5 to 4
    times faster on the benchmark meshes (decimated-max Laplacian: 2.0 -> 0.5 ms).

    Parameters
    ----------
    A : (n, n) sparse matrix
    symmetric : bool

    Examples
    --------
    >>> import numpy as np
    >>> solve = factor(sp.csr_matrix(np.array([[2.0, 1], [1, 3]])), symmetric=True)
    >>> np.allclose(solve(np.array([3.0, 4])), [1, 1])
    True
    """
    if symmetric and A.shape[0] > LARGE:
        return _cholesky(A)
    options = {"SymmetricMode": True} if symmetric else {}
    try:
        lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A" if symmetric else "COLAMD",
                       options=options)
    except RuntimeError as exc:  # SuperLU reports an exactly singular matrix this way
        raise SingularSystemError(str(exc)) from exc
    return lu.solve


def _cholesky(A):
    """libigl's sparse Cholesky of a symmetric positive definite ``A``: ``solve(b)``."""
    n = A.shape[0]
    data = igl.min_quad_with_fixed_data()
    # it reports no failure: the callers' matrices are positive definite by construction
    # (every part of the mesh holds a held vertex), and a non-finite result is caught later
    igl.min_quad_with_fixed_precompute(sp.csc_matrix(A, dtype=float), np.zeros(0, np.int64),
                                       sp.csc_matrix((0, n)), True, data)

    def solve(b):
        B = np.asarray(b, dtype=float)
        flat = B.ndim == 1
        B2 = -np.ascontiguousarray(B.reshape(n, -1))  # it minimizes 0.5 z'Az + z'B
        k = B2.shape[1]
        z = igl.min_quad_with_fixed_solve(data, B2, np.zeros((0, k)), np.zeros((0, k)))
        return z.ravel() if flat else z

    return solve
