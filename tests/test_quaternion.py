import numpy as np
from scipy.spatial.transform import Rotation

from srarap_cli.solver.quaternion import (
    from_axis_angle,
    multiply,
    normalize,
    rotate,
    to_matrix,
)


def test_rotate_and_matrix_agree_with_scipy():
    rng = np.random.default_rng(0)
    q = rng.normal(size=(50, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    v = rng.normal(size=(50, 3))
    expected = Rotation.from_quat(q[:, [1, 2, 3, 0]]).apply(v)  # scipy is scalar-last
    assert np.allclose(rotate(q, v), expected, atol=1e-12)
    assert np.allclose(np.einsum("nij,nj->ni", to_matrix(q), v), expected, atol=1e-12)


def test_multiply_composes_rotations():
    rng = np.random.default_rng(1)
    a, b = normalize(rng.normal(size=(2, 4)), np.zeros((2, 4)))
    v = rng.normal(size=3)
    assert np.allclose(rotate(multiply(a, b), v), rotate(a, rotate(b, v)), atol=1e-12)


def test_axis_angle_right_hand_rule():
    q = from_axis_angle([0, 0, 2], 90)
    assert np.allclose(rotate(q, np.array([1.0, 0, 0])), [0, 1, 0], atol=1e-15)


def test_normalize_keeps_fallback_for_zero_rows():
    out = normalize(np.array([[0.0, 0, 0, 0], [2.0, 0, 0, 0]]), np.array([[0, 1.0, 0, 0]] * 2))
    assert np.array_equal(out, [[0, 1, 0, 0], [1, 0, 0, 0]])
