"""Sparse factorizations shared by the Poisson solve and the rotor systems' preconditioner."""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import SingularSystemError

# Above this size SuperLU's minimum-degree ordering is what takes the time (on the 738k-vertex
# Laplacian it had not finished after 12 minutes). METIS's nested dissection orders it in 7 s
# and SuperLU then factors it in 6.6 s (80M entries), where libigl's Cholesky (Eigen, AMD)
# took 31 s and its 4-column solves were twice as slow as SuperLU's (0.21 against 0.10 s at
# 184k vertices). Below, minimum degree is as good or better (46k: 0.38 s factor, 24 ms solve;
# nested dissection 0.55 s, 23 ms).
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
        return _nested_dissection(A)
    options = {"SymmetricMode": True} if symmetric else {}
    try:
        lu = spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A" if symmetric else "COLAMD",
                       options=options)
    except RuntimeError as exc:  # SuperLU reports an exactly singular matrix this way
        raise SingularSystemError(str(exc)) from exc
    return lu.solve


def _nested_dissection(A):
    """SuperLU of a symmetric ``A`` in METIS's nested dissection order: ``solve(b)``."""
    import pymetis

    graph = sp.csr_matrix(A, dtype=float, copy=True)
    graph.setdiag(0)
    graph.eliminate_zeros()
    order = np.asarray(pymetis.nested_dissection(
        pymetis.CSRAdjacency(graph.indptr, graph.indices))[0], dtype=np.int64)
    permuted = sp.csc_matrix(sp.csr_matrix(A)[order][:, order])
    try:
        lu = spla.splu(permuted, permc_spec="NATURAL", options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise SingularSystemError(str(exc)) from exc

    def solve(b):
        B = np.asarray(b, dtype=float)
        out = np.empty_like(B)
        out[order] = lu.solve(np.ascontiguousarray(B[order]))
        return out

    return solve
