"""The Galerkin coarse-grid correction of issue 51's experiment (benchmarks/galerkin_correction.py,
not shipped): its coarse operator is ``P^T Q P``, its step the minimum of the energy's quadratic
model over the coarse space, and a solve corrected by it ends at the direct answer even where
the iteration's fixed point and the energy's minimum differ."""
import os
import sys
from types import SimpleNamespace

import numpy as np
import pytest
from helpers import bent_tube, diagonal, ends, tube, twist

from srarap_cli import Deformer
from srarap_cli.solver.hessian import energy_hessian, rotor_gradient
from srarap_cli.solver.multires import MultiresDeformer
from srarap_cli.solver.quaternion import from_rotation_vectors, multiply, normalize

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
import galerkin_correction as gc  # noqa: E402


@pytest.fixture(scope="module")
def small():
    """A bent tube of 54 vertices, its solve's rotors turned by a smooth field, 6 aggregates
    of rings (``cells``)."""
    d, T, r = bent_tube(tol=1e-8)
    V = d.V
    turn = np.outer(np.sin(V[:, 2]), [0.1, -0.05, 0.02])
    r = SimpleNamespace(positions=r.positions,
                        rotors=multiply(from_rotation_vectors(turn), r.rotors))
    cells = np.argsort(np.argsort(V[:, 2]), kind="stable") * 6 // len(V)
    return d, T, r, cells, gc.CoarseSpace(d.graph, cells, d.fixed)


def prolongation(space, n):
    """``P`` (n, m) column by column, from ``prolong``."""
    cols = []
    for a in range(space.m):
        z = np.zeros((space.m, 3))
        z[a, 0] = 1.0
        cols.append(space.prolong(z)[:, 0])
    return np.stack(cols, axis=1)


def coarse_basis(d, space):
    """The coarse space as dense columns of (u, w) (6n), in the operator's order: column
    ``6a + k`` moves aggregate ``a``'s positions along axis ``k`` (held vertices stay),
    ``6a + 3 + k`` turns its rotors about axis ``k``."""
    n, m = len(d.V), space.m
    P = prolongation(space, n)
    Pu = P.copy()
    Pu[d.fixed] = 0.0
    B = np.zeros((6 * n, 6 * m))
    for a in range(m):
        for k in range(3):
            B[k:3 * n:3, 6 * a + k] = Pu[:, a]
            B[3 * n + k::3, 6 * a + 3 + k] = P[:, a]
    return B


def hessian_columns(d, H, B):
    """``Q B`` from the Hessian's products (half the Hessian: ``Q_uu = 2 K``)."""
    n = len(d.V)
    out = []
    for x in B.T:
        u, w = x[:3 * n].reshape(n, 3), x[3 * n:].reshape(n, 3)
        out.append(np.concatenate([(2.0 * (d.graph.laplacian @ u) + H.coupling_t(w)).ravel(),
                                   (H.coupling(u) + H.rotations(w)).ravel()]))
    return np.stack(out, axis=1)


def test_the_coarse_operator_is_the_hessian_seen_through_the_prolongation(small):
    d, T, r, cells, space = small
    H = energy_hessian(d.graph, d.edges, r.positions, r.rotors, d.bending_weight)
    B = coarse_basis(d, space)
    expected = B.T @ hessian_columns(d, H, B)
    A = space.operator(H).toarray()
    assert np.allclose(A, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_the_prolongation_keeps_constants_and_ramps_at_borders(small):
    """Each vertex's weights sum to one (a constant field prolongs to itself); vertices
    inside an aggregate keep weight one, those at a border take weight from both sides."""
    d, T, r, cells, space = small
    P = prolongation(space, len(d.V))
    assert np.allclose(P.sum(axis=1), 1.0)
    border = np.zeros(len(d.V), dtype=bool)
    border[d.graph.I[cells[d.graph.I] != cells[d.graph.J]]] = True
    # (an edge of zero cotangent weight does not ramp: a few border vertices keep one)
    assert border.any() and (np.count_nonzero(P[border], axis=1) > 1).mean() > 0.8
    assert np.allclose(P[~border].max(axis=1), 1.0, rtol=0, atol=1e-12)


def test_the_correction_is_the_minimum_of_the_quadratic_model_over_the_coarse_space(small):
    """Dense algebra: the quadratic model ``2 g.w + x^T Q x`` minimized over the coarse
    space gives the correction's rotor increments (to the single precision of its factor)."""
    d, T, r, cells, space = small
    n = len(d.V)
    H = energy_hessian(d.graph, d.edges, r.positions, r.rotors, d.bending_weight)
    g = rotor_gradient(d.graph, d.edges, r.positions, r.rotors, d.bending_weight)
    B = coarse_basis(d, space)
    B = B[:, np.abs(B).sum(axis=0) > 0]  # aggregates of held vertices only: no positions
    z = np.linalg.solve(B.T @ hessian_columns(d, H, B),
                        -B.T @ np.concatenate([np.zeros(3 * n), g.ravel()]))
    w = (B @ z)[3 * n:].reshape(n, 3)
    step = d.step_for(T, 1e-12)
    delta = gc.GalerkinCorrection(space, step)(step.state(r.positions, r.rotors), None)
    expected = multiply(from_rotation_vectors(w), r.rotors) - r.rotors
    assert np.abs(w).max() > 1e-3
    assert np.allclose(delta, expected, rtol=0, atol=1e-4 * np.abs(expected).max())


@pytest.fixture
def galerkin(monkeypatch):
    from srarap_cli.solver.multires import MultiresDeformer as MD
    monkeypatch.setattr(MD, "coarse_correction", MD.coarse_correction)
    gc.install()


def test_at_the_fixed_point_the_correction_is_small_and_still_downhill(galerkin):
    """On a bar twisted 200 degrees the iteration's fixed point sits 2.5e-5 (relative)
    above the energy's minimum: there the correction is the small Newton step toward it,
    under 5% of the one after two iterations, and both lower the energy."""
    V, F = tube(length=10.0, rings=60, segments=32)
    ids = ends(V, 10.0)
    T = twist(V, ids, 10.0, 200)
    md = MultiresDeformer(V, F, ids, size=150)
    step = md.fine.step_for(T, 1e-12)
    tight = md.fine.solve(T, tol=1e-12, max_iter=3000)
    early = md.fine.solve(T, tol=1e-12, max_iter=2)
    sizes = []
    for result in (tight, early):
        state = step.state(step.positions(result.rotors), result.rotors)
        delta = md.coarse_correction(T, 1e-12)(state, None)
        R = normalize(result.rotors + delta, result.rotors)
        assert step.state(step.positions(R), R).total < state.total
        sizes.append(np.abs(delta).max())
    assert sizes[0] < 0.05 * sizes[1]
    # ... and a corrected solve still stops (the corrections end when they stop
    # shrinking), at the direct answer
    corrected = md.solve(T, tol=1e-6)
    direct = Deformer(V, F, ids).solve(T, tol=1e-10, max_iter=3000)
    assert corrected.converged and corrected.iterations < 100
    assert "corrected" in {row["step"] for row in corrected.log}
    assert corrected.energy <= direct.energy * (1 + 1e-5)
    assert np.abs(corrected.positions - direct.positions).max() < 1e-3 * diagonal(V)
