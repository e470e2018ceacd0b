"""The rotor system's matrix-free product against the assembled block matrix."""
import numpy as np
import scipy.sparse as sp
from helpers import torus

from srarap_cli.solver.local_step import rotor_system
from srarap_cli.solver.local_step.linear_sym import SymmetricRotorStep
from srarap_cli.solver.local_step.rotor_system import FreeRotorMatrix
from srarap_cli.solver.operators import cell_graph
from srarap_cli.solver.rest_edges import RestEdges


def test_product_and_assembly_equal_the_dense_block_matrix():
    rng = np.random.default_rng(3)
    D = rng.normal(size=(6, 4, 4))
    W = sp.random(6, 6, density=0.5, random_state=4, format="csr")
    dense = np.kron(-W.toarray(), np.eye(4))
    for i in range(6):
        dense[4 * i:4 * i + 4, 4 * i:4 * i + 4] += D[i]
    A = FreeRotorMatrix(D, W)
    v = rng.normal(size=24)
    assert np.allclose(A @ v, dense @ v, rtol=1e-14, atol=1e-14)
    assert np.array_equal(A.tocsr().toarray(), dense)


def test_direct_fallback_gives_the_conjugate_gradient_rotors(monkeypatch):
    V, F = torus(rings=10, segments=6)
    edges = RestEdges(cell_graph(V, F), V)
    constrained = np.zeros(len(V), dtype=bool)
    constrained[:6] = True
    system = SymmetricRotorStep(edges, constrained, alpha_area=0.5, feedback=0.01)
    rng = np.random.default_rng(8)
    S, s = edges.covariance(V + 0.1 * rng.normal(size=V.shape))
    R0 = rng.normal(size=(len(V), 4))
    R0 /= np.linalg.norm(R0, axis=1)[:, None]
    by_cg = system.step(S, s, R0)
    # a CG that reports failure sends the solve to the factorization of the assembled matrix
    failed = []
    monkeypatch.setattr(rotor_system, "conjugate_gradients",
                        lambda product, precondition, b, **kw: failed.append(1) or
                        (np.zeros_like(b), 1))
    direct = system.step(S, s, R0)
    assert failed and not np.array_equal(direct, by_cg)  # the factorization's answer
    assert np.allclose(direct, by_cg, atol=1e-8)


def test_blocked_conjugate_gradients_solve_the_system_and_stop_as_scipys_test_says():
    """The same recurrences and stopping test as SciPy's cg: the same iterations, and
    answers that agree to rounding; a budget too small reports it (info = maxiter)."""
    import scipy.sparse.linalg as spla

    from srarap_cli.solver.local_step.block_cg import conjugate_gradients

    rng = np.random.default_rng(5)
    n = 300
    W = sp.random(n, n, density=0.02, random_state=6, format="csr")
    W = W + W.T
    D = np.tile(np.eye(4), (n, 1, 1)) * (np.asarray(W.sum(axis=1)).ravel() + 1.0)[:, None, None]
    A = FreeRotorMatrix(D, W)
    b = rng.normal(size=4 * n)
    diag = np.repeat(D[:, 0, 0], 4)
    ours, theirs = [], []

    def counted(seen):
        def precondition(r):
            seen.append(1)
            return r / diag
        return precondition

    x, info = conjugate_gradients(A.product, counted(ours), b, rtol=1e-10, atol=0.0,
                                  maxiter=500)
    y, info_scipy = spla.cg(A, b, rtol=1e-10, atol=0.0, maxiter=500,
                            M=spla.LinearOperator(A.shape, matvec=counted(theirs), dtype=float))
    assert info == info_scipy == 0 and len(ours) == len(theirs) > 3
    assert np.linalg.norm(A @ x - b) < 1e-10 * np.linalg.norm(b)
    assert np.allclose(x, y, rtol=1e-8, atol=1e-12)
    short, stopped = conjugate_gradients(A.product, counted([]), b, 1e-14, 0.0, 2)
    assert stopped == 2 and np.linalg.norm(A @ short - b) > 1e-6 * np.linalg.norm(b)
    assert conjugate_gradients(A.product, counted([]), np.zeros(4 * n), 1e-10, 0.0, 5)[1] == 0
