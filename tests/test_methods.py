"""The method family: shared guarantees, agreement with each other and with libigl."""
import igl
import numpy as np
import pytest
from helpers import ends, tube

from srarap_cli import Deformer, deform
from srarap_cli.solver.local_step import METHODS
from srarap_cli.solver.local_step.linear_sym import symmetric_weights
from srarap_cli.solver.local_step.membrane import membrane_matrices
from srarap_cli.solver.local_step.relax import best_unit_rotor, colour_classes
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix

V, F = tube()
IDS = ends(V)
DIAG = np.linalg.norm(np.ptp(V, axis=0))


def bent():
    T = V[IDS].copy()
    top = T[:, 2] > 1
    T[top] = (T[top] - [0, 0, 6]) @ to_matrix(from_axis_angle([0, 1, 0], 60)).T + [2, 0, 5]
    return T


@pytest.mark.slow
@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_reproduces_a_rigid_motion_exactly(method):
    Rm = to_matrix(from_axis_angle([1, -2, 0.5], 150))
    t = np.array([1.0, 2.0, -3.0])
    r = deform(V, F, IDS, V[IDS] @ Rm.T + t, method=method, max_iter=3000, tol=1e-13)
    assert np.abs(r.positions - (V @ Rm.T + t)).max() < 1e-8
    assert r.log[-1]["total"] < 1e-12 * np.sum(np.ptp(V, axis=0) ** 2)


def test_relaxation_and_symmetric_linear_step_reach_the_same_minimum():
    """The linearized step drops each cell's unit-length multiplier, whose size is about the
    cell's smallest membrane eigenvalue; relative to the bending weight of the row it is
    kappa = max_i lam_min(M_i) / (alpha A sum_j W_ij). Both methods minimize one energy, so
    their minima may differ by at most that relative amount."""
    sym = Deformer(V, F, IDS, method="sr-linear-sym", feedback=0.0)
    relax = Deformer(V, F, IDS, method="sr-relax", sweeps=30, feedback=0.0)
    a = sym.solve(bent(), max_iter=5000, tol=1e-13)
    b = relax.solve(bent(), max_iter=5000, tol=1e-13)
    assert a.converged and b.converged
    S, s = relax.edges.covariance(b.positions)
    lam_min = np.linalg.eigvalsh(membrane_matrices(S, s))[:, 0]
    row = relax.settings.alpha * relax.area * relax.graph.cell_sum(symmetric_weights(relax.graph))
    kappa = float((lam_min / row).max())
    gap = abs(a.energy - b.energy) / b.energy
    assert gap <= kappa, (gap, kappa)
    assert b.energy <= a.energy * (1 + 1e-12)  # exact per-cell minimization goes lower
    assert np.linalg.norm(a.positions - b.positions, axis=1).max() < 1e-2 * DIAG


@pytest.mark.slow
def test_paper_step_ends_above_the_total_energy_minimum():
    a = deform(V, F, IDS, bent(), method="sr-linear", max_iter=5000, tol=1e-12)
    b = deform(V, F, IDS, bent(), method="sr-relax", sweeps=30, max_iter=5000, tol=1e-12)
    assert b.energy < a.energy < 1.05 * b.energy


def test_arap_matches_libigl_arap_after_convergence():
    """libigl with the spokes energy and unclamped cotangents is the same energy as ours."""
    d = Deformer(V, F, IDS, method="arap", weights="cotan")
    ours = d.solve(bent(), max_iter=20000, tol=1e-14)
    data = igl.ARAPData()
    data.max_iter = 20000
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    igl.arap_precomputation(V, F, 3, IDS.astype(np.int32), data)
    theirs = igl.arap_solve(bent(), data, d.solve(bent(), max_iter=0).positions)
    assert np.linalg.norm(theirs - ours.positions, axis=1).max() < 1e-6 * DIAG
    assert ours.log[-1]["bending"] == 0.0


def test_relaxation_update_is_the_exact_cell_minimizer():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(200, 4, 4))
    M = A @ A.transpose(0, 2, 1) * rng.random((200, 1, 1))
    b = rng.normal(size=(200, 4)) * rng.random((200, 1))
    b[:3] = 0.0
    lam, Q = np.linalg.eigh(M)
    R = best_unit_rotor(lam, Q, b, np.tile([1.0, 0, 0, 0], (200, 1)))
    f = lambda X: np.einsum("ki,kij,kj->k", X, M, X) - 2 * np.einsum("ki,ki->k", b, X)
    assert np.allclose(np.linalg.norm(R, axis=1), 1)
    for X in rng.normal(size=(500, 200, 4)):
        assert (f(R) <= f(X / np.linalg.norm(X, axis=1, keepdims=True)) + 1e-9).all()


def test_colour_classes_never_put_neighbours_together():
    g = Deformer(V, F, IDS).graph
    classes = colour_classes(g)
    colour = np.empty(g.n, int)
    for k, cls in enumerate(classes):
        colour[cls] = k
    assert sorted(np.concatenate(classes)) == list(range(g.n))
    assert (colour[g.I] != colour[g.J]).all()


def test_unknown_method_is_rejected():
    with pytest.raises(ValueError, match="method must be one of"):
        Deformer(V, F, IDS, method="fast")


@pytest.mark.parametrize("method", sorted(METHODS))
def test_the_settings_a_method_owns_reach_its_constructor(method):
    """The settings table's ``method`` column is the only link between a setting and its local
    step: each one it names is a keyword of that step's constructor, and no other method
    gets it."""
    import inspect

    from srarap_cli.solver.settings import SETTINGS, resolve

    owned = {s.name for s in SETTINGS if s.method == method}
    options = resolve({"method": method}).method_options()
    assert set(options) == owned
    assert owned <= set(inspect.signature(METHODS[method]).parameters)
    assert any(s.method for s in SETTINGS)  # the column is used (sweeps: sr-relax)
