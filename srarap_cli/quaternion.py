"""Vectorized unit-quaternion (rotor) helpers.

Quaternions are stored as ``(..., 4)`` float arrays in ``(w, x, y, z)`` order. A rotor
``R`` acts on a vector ``v`` by the sandwich product ``R v R~``; in the paper's geometric
algebra the same rotor is ``w + B`` with the bivector ``B`` dual to ``(x, y, z)``.
"""
import numpy as np

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def multiply(a, b):
    """Hamilton product ``a * b`` of quaternion arrays broadcast against each other.

    Parameters
    ----------
    a, b : (..., 4) float arrays

    Returns
    -------
    (..., 4) float array

    Examples
    --------
    >>> multiply(np.array([0., 1, 0, 0]), np.array([0., 0, 1, 0]))  # i * j = k
    array([0., 0., 0., 1.])
    """
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ], axis=-1)


def rotate(q, v):
    """Rotate vectors ``v`` by unit quaternions ``q`` (``q v q~``).

    Parameters
    ----------
    q : (..., 4) float array of unit quaternions
    v : (..., 3) float array

    Returns
    -------
    (..., 3) float array
    """
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def to_matrix(q):
    """Rotation matrices of unit quaternions: ``(..., 4) -> (..., 3, 3)``."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=-2)


def from_axis_angle(axis, degrees):
    """Unit quaternion rotating by ``degrees`` about ``axis`` (right-hand rule).

    Parameters
    ----------
    axis : (3,) float array, any non-zero length
    degrees : float

    Examples
    --------
    >>> np.round(rotate(from_axis_angle([0, 0, 1], 90), np.array([1., 0, 0])), 12)
    array([0., 1., 0.])
    """
    axis = np.asarray(axis, dtype=float)
    half = np.deg2rad(degrees) / 2.0
    return np.concatenate([[np.cos(half)], np.sin(half) * axis / np.linalg.norm(axis)])


def normalize(q, fallback):
    """Scale quaternions to unit length; rows too short to normalize take ``fallback``.

    Parameters
    ----------
    q, fallback : (n, 4) float arrays
    """
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    ok = norm[:, 0] > 1e-300
    out = np.array(fallback, dtype=float, copy=True)
    out[ok] = q[ok] / norm[ok]
    return out
