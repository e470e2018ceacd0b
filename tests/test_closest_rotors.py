"""closest_rotors against the SVD solution of the rotation-constrained Procrustes problem."""
import numpy as np
import pytest

from srarap_cli.solver import closest_rotors as module
from srarap_cli.solver.closest_rotors import closest_rotors
from srarap_cli.solver.quaternion import IDENTITY, from_axis_angle, to_matrix

rng = np.random.default_rng(7)


def _rotations(m):
    q = rng.normal(size=(m, 4))
    return to_matrix(q / np.linalg.norm(q, axis=1)[:, None])


def _svd_rotations(S):
    """``U diag(1, 1, det(U V^T)) V^T``: the textbook answer, computed independently."""
    U, _, Vt = np.linalg.svd(S)
    d = np.ones((len(S), 3))
    d[:, 2] = np.sign(np.linalg.det(U @ Vt))
    return np.einsum("nij,nj,njk->nik", U, d, Vt)


def _cases():
    """Covariances of every kind a mesh produces: generic, flat cells (rank 2), nearly flat,
    reflected (det < 0), pure rotations (half turns included), rotations by 170-180 degrees."""
    half_turns = np.array([to_matrix(from_axis_angle(rng.normal(size=3), a))
                           for a in rng.uniform(170, 180, 200)])
    return np.concatenate([
        rng.normal(size=(500, 3, 3)),
        _rotations(300) @ np.diag([3.0, 2.0, 0.0]) @ _rotations(300),
        _rotations(300) @ np.diag([3.0, 2.0, 1e-4]),
        _rotations(300) @ np.diag([3.0, 2.0, -1.0]),
        _rotations(300),
        half_turns @ np.diag([2.0, 1.5, 0.5]),
    ])


@pytest.mark.parametrize("reference", ["identity", "random"])
def test_matches_the_svd_solution(reference):
    S = _cases()
    ref = (np.tile(IDENTITY, (len(S), 1)) if reference == "identity"
           else rng.normal(size=(len(S), 4)))
    ref /= np.linalg.norm(ref, axis=1)[:, None]
    q = closest_rotors(S, ref)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-14)
    # well-separated cases: the rotation itself agrees to rounding
    assert np.abs(to_matrix(q) - _svd_rotations(S)).max() < 1e-10
    # the sign follows the reference
    assert (np.einsum("ij,ij->i", q, ref) >= 0).all()


def test_every_column_choice_and_the_eigh_fallback_agree_with_svd(monkeypatch):
    """Rotations near a half turn need another adjugate column; force every cell through
    each path in turn."""
    S = _cases()
    ref = rng.normal(size=(len(S), 4))
    ref /= np.linalg.norm(ref, axis=1)[:, None]
    expected = _svd_rotations(S)
    monkeypatch.setattr(module, "_MIN_WEIGHT", 2.0)  # no column is good enough: eigh
    assert np.abs(to_matrix(closest_rotors(S, ref)) - expected).max() < 1e-10


def test_undetermined_rotations_are_maximizers_nearest_the_reference():
    axis_only = np.diag([1.0, 0.0, 0.0])[None]      # rank 1: any turn about x fits
    zero = np.zeros((1, 3, 3))
    ref = from_axis_angle([1, 1, 0], 40)[None]
    q = closest_rotors(np.concatenate([axis_only, zero]), np.repeat(ref, 2, axis=0))
    assert np.allclose(q[1], ref[0])                # nothing to fit: keep the reference
    R = to_matrix(q[0])
    assert np.isclose(np.trace(R.T @ axis_only[0]), 1.0)   # maps x to x: a maximizer
    # among the turns about x, the one nearest the reference (projection onto w and x)
    nearest = np.array([ref[0, 0], ref[0, 1], 0.0, 0.0])
    assert np.allclose(q[0], nearest / np.linalg.norm(nearest))


def test_blocks_give_the_same_result_as_one_pass(monkeypatch):
    S = _cases()
    ref = np.tile(IDENTITY, (len(S), 1))
    whole = closest_rotors(S, ref)
    monkeypatch.setattr(module, "_BLOCK", 97)
    assert np.array_equal(closest_rotors(S, ref), whole)
