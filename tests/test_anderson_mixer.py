"""Anderson mixing on linear maps, where its behaviour is known exactly.

On an affine map ``y -> A y + c`` of dimension ``k``, type-II Anderson with a history of at
least ``k`` differences is GMRES followed by one map (Walker & Ni 2011): from a generic start
it lands on the fixed point ``(I - A)^-1 c`` after ``k + 2`` maps (up to rounding).
"""
import numpy as np

from srarap_cli.solver.drivers.anderson import AndersonMixer


def _contraction(k, seed):
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((k, k)))
    A = Q @ np.diag(rng.uniform(0.5, 0.95, k)) @ Q.T  # spectral radius 0.95: plain is slow
    return A, rng.standard_normal(k)


def test_mixing_reaches_the_fixed_point_of_an_affine_map_in_k_plus_2_maps():
    A, c = _contraction(5, seed=1)
    fixed = np.linalg.solve(np.eye(5) - A, c)
    mixer, y = AndersonMixer(5), np.zeros(5)
    for _ in range(7):
        g = A @ y + c
        y = mixer.mix(g, g - y)
    assert np.linalg.norm(y - fixed) < 1e-8 * np.linalg.norm(fixed)
    plain = np.zeros(5)
    for _ in range(7):
        plain = A @ plain + c
    assert np.linalg.norm(plain - fixed) > 0.1 * np.linalg.norm(fixed)


def test_a_residual_that_determines_the_state_mixes_the_whole_state():
    # the state is (y, z) with z = B y + d a function of y (as positions are of rotors):
    # weights from the y part alone must carry z to its fixed point as well
    A, c = _contraction(4, seed=2)
    B = np.random.default_rng(3).standard_normal((3, 4))
    d = np.array([1.0, -2.0, 0.5])
    fixed_y = np.linalg.solve(np.eye(4) - A, c)
    mixer, y = AndersonMixer(4), np.zeros(4)
    for _ in range(6):
        gy = A @ y + c
        g = np.concatenate([gy, B @ gy + d])
        x = mixer.mix(g, gy - y)
        y = x[:4]
    assert np.allclose(y, fixed_y, rtol=0, atol=1e-8)
    assert np.allclose(x[4:], B @ fixed_y + d, rtol=0, atol=1e-8)


def test_the_first_mix_returns_the_map_value_itself():
    mixer, g = AndersonMixer(3), np.arange(4.0)
    assert mixer.mix(g, g[:2]) is g
