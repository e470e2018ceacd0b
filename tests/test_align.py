"""The best rigid motion between corresponding points (``tasks/comparison/align.py``)."""
import numpy as np
from scipy.spatial.transform import Rotation

from srarap_cli.tasks.comparison.align import rigid_motion


def test_a_known_motion_is_found_and_undone():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(50, 3))
    for _ in range(5):
        R, t = Rotation.random(random_state=rng).as_matrix(), rng.normal(size=3) * 10
        B = (A - t) @ R  # B = R^T (A - t): the motion that brings B back is (R, t)
        m = rigid_motion(A, B)
        assert np.allclose(m["rotation"], R, atol=1e-10)
        assert np.allclose(m["translation"], t, atol=1e-9)
        assert np.allclose(B @ np.array(m["rotation"]).T + m["translation"], A, atol=1e-9)
        angle = np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)))
        assert np.isclose(m["angle"], angle) and np.isclose(np.linalg.norm(m["axis"]), 1)


def test_a_mirror_image_gets_the_closest_rotation_not_a_reflection():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(30, 3))
    m = rigid_motion(A, A * [-1, 1, 1])
    assert np.isclose(np.linalg.det(m["rotation"]), 1.0)


def test_no_motion_is_the_identity_and_a_half_turn_has_its_axis():
    A = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]])
    m = rigid_motion(A, A)
    assert np.allclose(m["rotation"], np.eye(3)) and m["angle"] < 1e-12
    assert m["axis"] == [0, 0, 1]
    half = rigid_motion(A, A * [-1, -1, 1])
    assert np.isclose(half["angle"], 180) and np.allclose(np.abs(half["axis"]), [0, 0, 1])
