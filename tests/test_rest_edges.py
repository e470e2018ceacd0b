"""RestEdges' per-iteration sums against per-vertex brute force, in one block or many."""
import numpy as np
import pytest
from helpers import torus

from srarap_cli.runtime import parallel
from srarap_cli.solver.energy import bending_energy
from srarap_cli.solver.operators import cell_graph
from srarap_cli.solver.quaternion import to_matrix
from srarap_cli.solver.rest_edges import RestEdges


@pytest.fixture
def deformed_torus():
    V, F = torus(rings=10, segments=6)
    rng = np.random.default_rng(11)
    P = V + 0.2 * rng.normal(size=V.shape)
    R = rng.normal(size=(len(V), 4))
    return V, F, P, R / np.linalg.norm(R, axis=1)[:, None]


def test_rotated_divergence_is_the_sum_of_both_cells_rotated_edges(deformed_torus):
    V, F, _, R = deformed_torus
    g = cell_graph(V, F)
    Rm = to_matrix(R)
    b = RestEdges(g, V).rotated_divergence(R)
    for i in (0, 17, len(V) - 1):
        j, c = g.J[g.I == i], g.c[g.I == i]
        q = V[j] - V[i]
        rotated = q @ Rm[i].T + np.einsum("jab,jb->ja", Rm[j], q)
        assert np.allclose(b[i], 0.5 * (c[:, None] * rotated).sum(axis=0), rtol=1e-13,
                           atol=1e-13)


def test_edge_blocks_cover_every_edge_once(monkeypatch):
    V, F = torus(rings=10, segments=6)
    g = cell_graph(V, F)
    monkeypatch.setitem(parallel.PLANS, "edges", parallel.Plan(7, even=False))
    blocks = g.edge_blocks()
    assert len(blocks) == -(-g.I.size // 7)
    assert np.array_equal(np.concatenate([np.arange(g.I.size)[e] for e in blocks]),
                          np.arange(g.I.size))
    assert g.edge_blocks(0) == []


def test_sums_in_many_blocks_equal_one_block_and_brute_force(deformed_torus, monkeypatch):
    V, F, P, R = deformed_torus
    g = cell_graph(V, F)
    edges = RestEdges(g, V)
    whole = edges.stretch(P), edges.stretch_total(P), bending_energy(g, R, 0.3, 2.0)
    monkeypatch.setitem(parallel.PLANS, "edges", parallel.Plan(13, even=False))  # split rings
    s, total, bending = edges.stretch(P), edges.stretch_total(P), bending_energy(g, R, 0.3, 2.0)
    assert np.allclose(s, whole[0], rtol=1e-14)
    assert np.isclose(total, whole[1], rtol=1e-14)
    assert np.isclose(bending, whole[2], rtol=1e-14)
    # per vertex: s_i = sum_j c_ij (|p_ij|^2 + |q_ij|^2); bending with the closer sign
    brute_s = np.zeros(len(V))
    brute_bending = 0.0
    for i in range(len(V)):
        j, c = g.J[g.I == i], g.c[g.I == i]
        brute_s[i] = np.sum(c * (np.sum((P[j] - P[i]) ** 2, 1) + np.sum((V[j] - V[i]) ** 2, 1)))
        closer = np.minimum(np.sum((R[j] - R[i]) ** 2, 1), np.sum((R[j] + R[i]) ** 2, 1))
        brute_bending += 0.3 * 2.0 * closer.sum() / len(j)
    assert np.allclose(s, brute_s, rtol=1e-13)
    assert np.isclose(total, brute_s.sum(), rtol=1e-13)
    assert np.isclose(bending, brute_bending, rtol=1e-13)
