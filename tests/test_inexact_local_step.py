"""The local step's rotor system solved inexactly (a forcing term) and what that may change."""
import numpy as np
import pytest
from helpers import ends, tube

import srarap_cli.solver.local_step.rotor_system as rotor_system
import srarap_cli.solver.step as step_module
from srarap_cli import Deformer
from srarap_cli.solver.quaternion import from_axis_angle, to_matrix


@pytest.fixture(scope="module")
def bent():
    V, F = tube(length=6.0, rings=16, segments=8)
    ids = ends(V)
    T = V[ids].copy()
    top = T[:, 2] > 3
    turn = to_matrix(from_axis_angle([0, 1, 0], 70.0))
    T[top] = (T[top] - [0, 0, 6]) @ turn.T + [2.5, 0, 4.5]
    return V, F, ids, T


def _cg_residuals(monkeypatch):
    """Record (initial, final) residual norms of every rotor-system solve."""
    seen, cg = [], rotor_system.conjugate_gradients

    def recording_cg(product, precondition, r0, **kw):  # r0: the start's residual
        x, info = cg(product, precondition, r0, **kw)
        Ax = np.empty_like(x)
        product(x, Ax)
        seen.append((np.linalg.norm(r0), np.linalg.norm(r0 - Ax), kw["atol"]))
        return x, info
    monkeypatch.setattr(rotor_system, "conjugate_gradients", recording_cg)
    return seen


def test_each_solve_meets_its_forcing_or_the_rounding_floor(bent, monkeypatch):
    V, F, ids, T = bent
    seen = _cg_residuals(monkeypatch)
    Deformer(V, F, ids).solve(T, tol=1e-6, max_iter=30)
    assert len(seen) > 10
    forcing = step_module.local_forcing(1e-6)
    for start, end, floor in seen:
        assert end <= max(forcing * start, floor) * (1 + 1e-12)
    # and the forcing, not the rounding floor, ended most solves (the work it saves)
    assert sum(end > 10 * floor for _, end, floor in seen) > len(seen) / 2


def test_forcing_follows_the_tolerance():
    # never looser than MAX_FORCING, tighter for tight solves, exact for tol 0
    assert step_module.local_forcing(1.0) == step_module.MAX_FORCING
    assert step_module.local_forcing(1e-10) == pytest.approx(1e-5)
    assert step_module.local_forcing(0.0) == 0.0


def test_inexact_and_exact_local_steps_reach_the_same_shape(bent, monkeypatch):
    """Run to tol 1e-12 once with the default forcing of tol 1e-6 kept throughout and once
    with exact solves: the fixed points differ only by the inexact solve's bias (1.0e-6 of the
    diagonal here), well below what a default stop is from a tight solve (1e-5 to 1e-4 of the
    diagonal on the benchmark cases)."""
    V, F, ids, T = bent
    d = Deformer(V, F, ids)
    monkeypatch.setattr(step_module, "local_forcing", lambda tol: 0.0)
    exact = d.solve(T, tol=1e-12, max_iter=3000)
    monkeypatch.setattr(step_module, "local_forcing", lambda tol: step_module.MAX_FORCING)
    loose = d.solve(T, tol=1e-12, max_iter=3000)
    assert exact.converged and loose.converged
    diag = np.linalg.norm(np.ptp(V, axis=0))
    assert np.linalg.norm(loose.positions - exact.positions, axis=1).max() < 1e-5 * diag
    assert abs(loose.energy / exact.energy - 1) < 1e-6
