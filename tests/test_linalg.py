"""Both factorization back ends solve the same systems."""
import numpy as np
import scipy.sparse as sp
from helpers import ends, tube

from srarap_cli import Deformer, linalg
from srarap_cli.quaternion import from_axis_angle, to_matrix


def test_nested_dissection_back_end_solves_spd_systems(monkeypatch):
    rng = np.random.default_rng(1)
    M = sp.random(30, 30, density=0.2, random_state=2)
    A = (M @ M.T + sp.eye(30) * 0.5).tocsr()
    b = rng.standard_normal((30, 4))
    monkeypatch.setattr(linalg, "LARGE", 0)
    solve = linalg.factor(A, symmetric=True)
    assert np.abs(A @ solve(b) - b).max() < 1e-10
    assert np.abs(A @ solve(b[:, 0]) - b[:, 0]).max() < 1e-10
    assert solve(b[:, 0]).shape == (30,)


def test_large_mesh_back_end_gives_the_same_deformation(monkeypatch):
    V, F = tube(length=6.0, rings=12, segments=8)
    ids = ends(V, 6.0)
    T = V[ids].copy()
    top = T[:, 2] > 3
    T[top] = T[top] @ to_matrix(from_axis_angle([0, 0, 1], 90)).T
    small = Deformer(V, F, ids).solve(T, max_iter=30)
    monkeypatch.setattr(linalg, "LARGE", 0)
    large = Deformer(V, F, ids).solve(T, max_iter=30)
    assert small.iterations == large.iterations
    assert np.abs(small.positions - large.positions).max() < 1e-8
