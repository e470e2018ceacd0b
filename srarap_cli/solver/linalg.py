"""Sparse factorizations shared by the Poisson solve and the rotor systems' preconditioner."""
import contextlib
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csr_matrix

from ..runtime.errors import SingularSystemError
from ..runtime.forking import how
from ..runtime.fpu import subnormals_flushed
from ..runtime.fresh_process import run_fresh
from ..runtime.limits import is_out_of_memory
from ..runtime.signals import deferred
from ..runtime.streams import held_c_stderr
from .one_triangle import backend, rslab_factor

# Above this size SuperLU's minimum-degree ordering is what takes the time (on the 738k-vertex
# Laplacian it had not finished after 12 minutes). METIS's nested dissection orders it in 7 s
# and SuperLU then factors it in 6.6 s (80M entries), where libigl's Cholesky (Eigen, AMD)
# took 31 s and its 4-column solves were twice as slow as SuperLU's (0.21 against 0.10 s at
# 184k vertices). Below, minimum degree is as good or better (46k: 0.38 s factor, 24 ms solve;
# nested dissection 0.55 s, 23 ms).
LARGE = 200_000
#: rows from which a symmetric matrix goes to rslab (unless $SRARAP_FACTOR names one): below,
#: SuperLU's solves were faster, which a small mesh's iterations are made of (4-column solve,
#: SuperLU / rslab: 11.5k rows 2.0-3.6 / 4.4 ms, 46k 12.6-15.2 / 18-24 ms; the convergence
#: benchmark's small meshes 10-30% slower to the stop with rslab); at 184k rslab factors
#: 1.4-2 times faster and solves as fast (74 ms either), with half the factor memory
ONE_TRIANGLE_FROM = 100_000


def _warm_blas():
    """Have OpenBLAS take its work buffer now, while memory is free.

    OpenBLAS allocates that buffer (32 MB) on its first use and, when the allocation fails,
    retries forever: under ``ulimit -v`` a SuperLU factorization reaching its first BLAS call
    with the address space nearly used spun at full CPU instead of failing (seen: minutes,
    deaf to SIGTERM). A buffer taken early is reused by every later call."""
    import resource

    if resource.getrlimit(resource.RLIMIT_AS)[0] == resource.RLIM_INFINITY:
        return
    from scipy.linalg import blas

    one = np.ones((1, 1), order="F")
    blas.dtrsv(one, np.ones(1))
    blas.dgemm(1.0, one, one)


_warm_blas()


def factor(A: csr_matrix, symmetric: bool, order: Callable | None = None, approximate: bool = False
           ) -> Callable:
    """Factor a sparse square matrix; returns a callable ``solve(b)``.

    A symmetric positive definite matrix of :data:`ONE_TRIANGLE_FROM` rows or more is
    factored by rslab (:mod:`.one_triangle`: one stored triangle, half SuperLU's memory,
    faster) where it can be; everything else by SuperLU. For SuperLU, a symmetric matrix
    gets a symmetric fill-reducing ordering, which roughly halves the fill of SuperLU's
    default column ordering on mesh Laplacians, and SuperLU's symmetric mode (diagonal
    pivots preferred): with the same fill, its triangular solves ran 1.5 to 4 times faster
    on the benchmark meshes (decimated-max Laplacian: 2.0 -> 0.5 ms).

    Parameters
    ----------
    A : (n, n) sparse matrix
    symmetric : bool
    order : callable, optional, returning a fill-reducing permutation of A's rows; called only
        for a large symmetric ``A`` (nested dissection), default METIS on A's own graph
    approximate : bool, an approximate solve is enough (a preconditioner): a symmetric ``A``
        is then factored in single precision, which halves the memory its factors take and the
        traffic of its triangular solves (rotor preconditioner, 4-column solve: 3.6 -> 2.5 ms
        at 11k vertices, 18 -> 11 ms at 50k, 0.20 -> 0.16 s at 738k), with subnormal numbers
        flushed to zero (see :mod:`..runtime.fpu`); the solution comes back in double precision

    Examples
    --------
    >>> import numpy as np
    >>> solve = factor(sp.csr_matrix(np.array([[2.0, 1], [1, 3]])), symmetric=True)
    >>> np.allclose(solve(np.array([3.0, 4])), [1, 1])
    True
    """
    scale = 1.0
    if symmetric and approximate:
        # single precision spans 1e-38 to 3e38 only: the matrix (and each right-hand side,
        # in the solve) brought to unit size keep meshes of any units inside it
        scale = float(abs(A).max()) or 1.0
        A = A / scale
    ldlt = rslab_factor(A, single=approximate) if symmetric and _one_triangle(A) else None
    if ldlt is not None:
        return _rslab_solver(ldlt, scale, approximate)
    if symmetric and approximate:
        A = A.astype(np.float32)
    if symmetric and A.shape[0] > LARGE:
        return _nested_dissection(A, fill_order(A) if order is None else order(), scale)
    options = {"SymmetricMode": True} if symmetric else {}
    A = sp.csc_matrix(A)
    with _flushed(A.dtype == np.float32):
        lu = _superlu(A, "MMD_AT_PLUS_A" if symmetric else "COLAMD", options)
    return _solver(lu, A.dtype, scale)


def _superlu(A, permc_spec, options):
    """``splu`` with its failures as our errors. SuperLU prints a failed allocation on the C
    stderr itself ("malloc fails for local dworkptr[]."): that text is held back and dropped
    when the failure is reported as one line anyway."""
    try:
        with held_c_stderr():
            return spla.splu(A, permc_spec=permc_spec, options=options)
    except RuntimeError as exc:  # SuperLU reports an exactly singular matrix this way
        if is_out_of_memory(exc):  # ... and a failed allocation too
            raise MemoryError(str(exc)) from None
        raise SingularSystemError(str(exc)) from exc


def _nested_dissection(A, order, scale=1.0):
    """SuperLU of a symmetric ``A`` in the order ``order``: ``solve(b)`` (of ``scale * A``)."""
    permuted = sp.csc_matrix(sp.csr_matrix(A)[order][:, order])
    dtype = permuted.dtype
    single = dtype == np.float32
    with _flushed(single):
        lu = _superlu(permuted, "NATURAL", {"SymmetricMode": True})
    # SuperLU keeps its own copy: the solve must not hold this one (62 MB at 738k vertices)
    del permuted
    inverse = np.empty_like(order)
    inverse[order] = np.arange(order.size)
    permuted_solve = _solver(lu, dtype, scale)

    def solve(b):
        # np.take gathers rows several times faster than fancy indexing, and a gather by the
        # inverse order replaces the scatter: 109 -> 30 ms a 4-column solve's copies at 738k
        X = permuted_solve(np.take(np.asarray(b), order, axis=0))
        return np.take(X, inverse, axis=0)

    return solve


def _solver(lu, dtype, scale=1.0):
    """``solve(b)`` of ``scale`` times the matrix SuperLU factored into ``lu`` (of precision
    ``dtype``), answering in double precision, row-major as rslab answers: SuperLU's
    column-major answer made every row gather (``np.take``) and sparse product of a block of
    rows copy the whole array first (a coarse level's positions, a dozen times a step)."""
    if dtype != np.float32:
        return lambda b: np.ascontiguousarray(lu.solve(b))

    def solve(b):
        b = np.asarray(b, dtype=float)
        size = max(float(b.max(initial=0.0)), -float(b.min(initial=0.0)))  # no |b| temporary
        if size == 0.0:
            return np.zeros(b.shape)
        B = np.empty(b.shape, dtype=dtype, order="F")
        np.divide(b, size, out=B, casting="same_kind")
        with _flushed(True):
            X = lu.solve(B)
        return np.multiply(X, size / scale, out=np.empty(X.shape), dtype=float)

    return solve


def _one_triangle(A):
    """Whether rslab may take the symmetric ``A``: asked for, or large enough unasked."""
    asked = backend()
    return asked == "rslab" or asked == "auto" and A.shape[0] >= ONE_TRIANGLE_FROM


def _rslab_solver(ldlt, scale, single):
    """``solve(b)`` of ``scale`` times the matrix factored into ``ldlt``, in double precision.
    A double-precision factor (``scale`` 1) solves as it is; a single-precision one gets each
    right-hand side brought to unit size, as SuperLU's."""

    def exact(b):
        b = np.ascontiguousarray(b, dtype=float)
        return ldlt.solve_many(b) if b.ndim == 2 else ldlt.solve(b)

    def approximate(b):
        b = np.asarray(b, dtype=float)
        size = max(float(b.max(initial=0.0)), -float(b.min(initial=0.0)))  # no |b| temporary
        if size == 0.0:
            return np.zeros(b.shape)
        return np.multiply(exact(b / size), size / scale)

    return approximate if single else exact


def _flushed(single):
    """Single-precision work flushes subnormals (its factor's fill decays to them); double
    precision keeps IEEE arithmetic."""
    return subnormals_flushed() if single else contextlib.nullcontext()


def fill_order(A: csr_matrix) -> np.ndarray:
    """METIS nested dissection order of the graph of a symmetric sparse matrix's stored
    off-diagonal entries (explicit zeros count); vertices without any come first.

    From :data:`APART_FROM` linked vertices on, where other threads run (the simplification
    beside it: :func:`..runtime.forking.how` ``gil``), METIS runs in a fresh interpreter
    (:mod:`..runtime.fresh_process`): it keeps the GIL for its whole run, which stalled
    them. The order is the same either way.

    Parameters
    ----------
    A : (n, n) sparse matrix

    Returns
    -------
    (n,) int64 array, a permutation of ``range(n)``
    """
    with deferred():  # a pybind11 module, as libigl (see solver.libigl)
        import pymetis

    coo = sp.coo_matrix(A)
    off = coo.row != coo.col
    graph = sp.csr_matrix((np.ones(off.sum()), (coo.row[off], coo.col[off])), shape=A.shape)
    linked = np.diff(graph.indptr) > 0
    ids = np.flatnonzero(linked)
    sub = graph[ids][:, ids]
    sub.sort_indices()
    apart = ids.size >= APART_FROM and how("gil") == "fresh"
    found = run_fresh(_DISSECTION, _adjacency_bytes(sub)) if apart else None
    order = (np.frombuffer(found, dtype="<i8") if found is not None and _is_permutation(found, ids.size)
             else _dissection(pymetis, sub.indptr, sub.indices))
    return np.concatenate([np.flatnonzero(~linked), ids[order]])


#: linked vertices from which METIS runs in another process: starting one (an interpreter,
#: numpy and pymetis) takes about 0.2 s, what METIS takes for about 35k vertices
APART_FROM = 100_000


def _dissection(pymetis, indptr, indices):
    adjacency = pymetis.CSRAdjacency(indptr, indices)
    return np.asarray(pymetis.nested_dissection(adjacency)[0], dtype=np.int64)


def _adjacency_bytes(sub):
    """The graph for :data:`_DISSECTION`: n, then indptr (n + 1) and indices, int64."""
    n = np.array([sub.shape[0]], dtype="<i8")
    return b"".join(np.ascontiguousarray(a, dtype="<i8").tobytes()
                    for a in (n, sub.indptr, sub.indices))


#: the child's side of :func:`fill_order` (source for :func:`run_fresh`)
_DISSECTION = """import numpy as np, pymetis
n = int(np.frombuffer(payload, "<i8", 1)[0])
indptr = np.frombuffer(payload, "<i8", n + 1, 8)
indices = np.frombuffer(payload, "<i8", offset=8 * (n + 2))
order = pymetis.nested_dissection(pymetis.CSRAdjacency(indptr, indices))[0]
sys.stdout.buffer.write(np.asarray(order, dtype="<i8").tobytes())
"""


def _is_permutation(found, n):
    """Whether the child's bytes are a permutation of ``range(n)``."""
    if len(found) != 8 * n:
        return False
    order = np.frombuffer(found, dtype="<i8")
    return bool(n == 0 or (order.min() >= 0 and order.max() < n
                           and np.bincount(order, minlength=n).max() == 1))
