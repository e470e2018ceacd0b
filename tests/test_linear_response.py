"""The warm start's first-order response to a move of the handles: its error shrinks with the
square of the move, and a re-solve after a small change needs only the stopping test's window."""
import numpy as np
import pytest
from helpers import ends, tube

from srarap_cli import Deformer
from srarap_cli.solver.quaternion import from_axis_angle, from_rotation_vectors, multiply, to_matrix
from srarap_cli.solver.starts import STARTS


@pytest.fixture(scope="module")
def solved():
    V, F = tube(length=6.0, rings=16, segments=10)
    ids = ends(V)
    d = Deformer(V, F, ids)
    T = V[ids].copy()
    top = T[:, 2] > 1
    T[top] = (T[top] - [0, 0, 6]) @ to_matrix(from_axis_angle([0, 1, 0], 40)).T + [1.0, 0, 5.5]
    return d, T, d.solve(T, tol=1e-12, max_iter=3000)


def start_error(d, T, first, kind, scale):
    """Distance over the diagonal from the start ``kind`` (after targets * scale) to the
    tight solve of the new targets."""
    new = T * scale
    step = d.step_for(new)
    start = STARTS[kind](step, (first.positions, first.rotors))
    tight = d.solve(new, tol=1e-12, max_iter=3000)
    return np.abs(start.positions - tight.positions).max() / d.diagonal


def test_the_predicted_start_is_second_order_in_the_move(solved):
    d, T, first = solved
    warm = [start_error(d, T, first, "warm", 1 + delta) for delta in (0.02, 0.01)]
    plain = [start_error(d, T, first, "extrapolated", 1 + delta) for delta in (0.02, 0.01)]
    # halving the move: error / 2 without the response, / 4 with it
    assert 1.6 < plain[0] / plain[1] < 2.5
    assert warm[0] / warm[1] > 3.2
    assert warm[1] < plain[1] / 20


def test_a_small_change_resolves_in_the_stopping_window(solved):
    d, T, first = solved
    new = T * 1.01
    warm = d.solve(new, initial=(first.positions, first.rotors))
    cold = d.solve(new)
    tight = d.solve(new, tol=1e-12, max_iter=3000)
    assert warm.converged and warm.iterations == 3 and cold.iterations > 9
    assert np.abs(warm.positions - tight.positions).max() < 1e-4 * d.diagonal


def test_the_extrapolated_start_is_used_when_asked(solved):
    d, T, first = solved
    new = T * 1.01
    plain = d.solve(new, initial=(first.positions, first.rotors), start="extrapolated",
                    max_iter=0)
    expected = STARTS["extrapolated"](d.step_for(new), (first.positions, first.rotors))
    assert np.array_equal(plain.positions, expected.positions)


def test_unchanged_targets_skip_the_response(solved):
    """Nothing moved: the start is the earlier state after one global step (no system solved,
    so no rounding added)."""
    d, T, first = solved
    step = d.step_for(T)
    warm = STARTS["warm"](step, (first.positions, first.rotors))
    plain = STARTS["extrapolated"](step, (first.positions, first.rotors))
    assert np.array_equal(warm.positions, plain.positions)
    assert np.abs(warm.positions - first.positions).max() < 1e-8 * d.diagonal


def test_the_response_is_the_derivative_of_the_solution(solved):
    """The rotors' response to a move against the central difference of tight solves. It is
    the derivative of the energy's minimum; the solver's fixed point sits a little off it
    (the normalized linear local step is not an exact minimization), and their derivatives
    differ by 2.2% here with the system solved to 1e-8 (2.3% to the default 1e-2)."""
    d, T, first = solved
    h = 1e-3
    plus = d.solve(T * (1 + h), tol=1e-13, max_iter=5000)
    minus = d.solve(T * (1 - h), tol=1e-13, max_iter=5000)
    moved = np.zeros((len(d.fixed), 3))
    moved[d.constrained_slots] = T * h
    w = d.linear_response.rotations(first.positions, first.rotors, moved)
    # the rotation taking minus to plus, as a vector, over the rotation taking first to plus
    turned_plus = _rotation_vectors(plus.rotors, first.rotors)
    turned_minus = _rotation_vectors(minus.rotors, first.rotors)
    derivative = (turned_plus - turned_minus) / 2
    assert np.abs(w - derivative).max() < 0.04 * np.abs(derivative).max()


def _rotation_vectors(R, R0):
    """Rotation vectors w with R = exp(w / 2) R0 (small rotations)."""
    q = multiply(R, R0 * [1, -1, -1, -1])
    q *= np.where(q[:, :1] < 0, -1.0, 1.0)
    half = np.arccos(np.clip(q[:, 0], -1, 1))
    scale = np.where(half > 1e-12, 2 * half / np.maximum(np.sin(half), 1e-300), 2.0)
    return q[:, 1:] * scale[:, None]


def test_rotation_vectors_match_axis_angle():
    rng = np.random.default_rng(5)
    for angle in (1e-7, 1e-5, 1e-4, 1e-3, 0.5, 3.0):
        axis = rng.standard_normal(3)
        axis /= np.linalg.norm(axis)
        q = from_rotation_vectors((angle * axis)[None])[0]
        assert np.allclose(q, from_axis_angle(axis, np.degrees(angle)), rtol=0, atol=1e-15)


def test_the_papers_system_keeps_the_rotations_only(solved):
    """sr-linear's fixed point is not the energy's minimum: no response is added."""
    d0, T, _ = solved
    d = Deformer(d0.V, d0.F, d0.constrained, method="sr-linear")
    first = d.solve(T, tol=1e-10, max_iter=3000)
    step = d.step_for(T * 1.01)
    warm = STARTS["warm"](step, (first.positions, first.rotors))
    plain = STARTS["extrapolated"](step, (first.positions, first.rotors))
    assert np.array_equal(warm.positions, plain.positions)
    assert d.local_step.near_minimum is False and d0.local_step.near_minimum is True
