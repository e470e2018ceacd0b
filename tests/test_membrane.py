"""M_i against a brute-force quaternion evaluation of the membrane residual."""
import numpy as np
from helpers import tube

from srarap_cli.solver.local_step.membrane import membrane_matrices
from srarap_cli.solver.operators import cell_graph
from srarap_cli.solver.quaternion import multiply
from srarap_cli.solver.rest_edges import RestEdges


def pure(v):
    return np.concatenate([np.zeros(v.shape[:-1] + (1,)), v], axis=-1)


def brute_residual(r, q, p, c):
    """sum_j c_j |r q_j - p_j r|^2 with explicit Hamilton products (any r, not only unit)."""
    res = multiply(r[None], pure(q)) - multiply(pure(p), r[None])
    return float(np.sum(c * np.sum(res ** 2, axis=1)))


def test_quadratic_form_equals_brute_force_on_random_edges():
    rng = np.random.default_rng(3)
    for _ in range(20):
        k = rng.integers(1, 9)
        q, p, c = rng.normal(size=(k, 3)), rng.normal(size=(k, 3)), rng.random(k)
        S = np.einsum("j,ja,jb->ab", c, p, q)[None]
        s = np.array([np.sum(c * (np.sum(p ** 2, 1) + np.sum(q ** 2, 1)))])
        M = membrane_matrices(S, s)[0]
        assert np.allclose(M, M.T)
        for _ in range(5):
            r = rng.normal(size=4)
            assert np.isclose(r @ M @ r, brute_residual(r, q, p, c), rtol=1e-11, atol=1e-11)


def test_unit_rotor_form_is_rotated_edge_mismatch():
    """For unit r: r^T M r = sum c |r q r~ - p|^2, and the exact rotor is a null vector."""
    rng = np.random.default_rng(4)
    q = rng.normal(size=(6, 3))
    r = rng.normal(size=4)
    r /= np.linalg.norm(r)
    rq = multiply(multiply(r[None], pure(q)), r * [1, -1, -1, -1])[:, 1:]
    c = rng.random(6)
    S = np.einsum("j,ja,jb->ab", c, rq, q)[None]
    s = np.array([np.sum(c * 2 * np.sum(q ** 2, 1))])
    M = membrane_matrices(S, s)[0]
    assert abs(r @ M @ r) < 1e-12 * s[0]
    assert np.linalg.eigvalsh(M).min() > -1e-12 * s[0]


def test_cell_covariance_matches_per_vertex_sums():
    V, F = tube(rings=3, segments=5)
    g = cell_graph(V, F)
    rng = np.random.default_rng(5)
    P = V + 0.1 * rng.normal(size=V.shape)
    S, s = RestEdges(g, V).covariance(P)
    i = 7
    nbr = g.J[g.I == i]
    cw = g.c[g.I == i]
    p_i, q_i = P[nbr] - P[i], V[nbr] - V[i]
    assert np.allclose(S[i], np.einsum("j,ja,jb->ab", cw, p_i, q_i))
    assert np.isclose(s[i], np.sum(cw * (np.sum(p_i ** 2, 1) + np.sum(q_i ** 2, 1))))
