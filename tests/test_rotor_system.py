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
    monkeypatch.setattr(rotor_system.spla, "cg", lambda A, b, **kw: (np.zeros_like(b), 1))
    direct = system.step(S, s, R0)
    assert np.allclose(direct, by_cg, atol=1e-8)
