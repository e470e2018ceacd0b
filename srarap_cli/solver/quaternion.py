"""Vectorized unit-quaternion (rotor) helpers.

Quaternions are stored as ``(..., 4)`` float arrays in ``(w, x, y, z)`` order. A rotor
``R`` acts on a vector ``v`` by the sandwich product ``R v R~``; in the paper's geometric
algebra the same rotor is ``w + B`` with the bivector ``B`` dual to ``(x, y, z)``.
"""

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.parallel import fill, splits

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
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


def _product_basis():
    """``T[a, b] = Lmul(e_a) Rmul(e_b)`` for the pure unit quaternions ``e_a, e_b``: (3, 3, 4, 4)."""
    eye = np.eye(4)
    T = np.empty((3, 3, 4, 4))
    for a in range(3):
        for b in range(3):
            # column k of Lmul(e_a) Rmul(e_b) is e_a * (e_k * e_b)
            T[a, b] = multiply(eye[1 + a], multiply(eye, eye[1 + b])).T
    return T


# sum_ab S_ab PRODUCT_BASIS[a, b] is the 4x4 matrix of r -> sum_ab S_ab e_a r e_b: the membrane
# (local_step.membrane) and Horn (closest_rotors) matrices are built from it
PRODUCT_BASIS = _product_basis()


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors ``v`` by unit quaternions ``q`` (``q v q~``).

    Parameters
    ----------
    q : (..., 4) float array of unit quaternions
    v : (..., 3) float array

    Returns
    -------
    (..., 3) float array
    """
    w, x, y, z = np.moveaxis(q, -1, 0)
    vx, vy, vz = np.moveaxis(v, -1, 0)
    # t = 2 u x v ; v' = v + w t + u x t  (written out: np.cross is slow on small rows)
    tx = 2 * (y * vz - z * vy)
    ty = 2 * (z * vx - x * vz)
    tz = 2 * (x * vy - y * vx)
    return np.stack([vx + w * tx + y * tz - z * ty,
                     vy + w * ty + z * tx - x * tz,
                     vz + w * tz + x * ty - y * tx], axis=-1)


def to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions: ``(..., 4) -> (..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 2 and splits(len(q)):  # a mesh's rotors: by blocks, on the threads
        return fill(_to_matrix, np.empty((len(q), 3, 3)), q)
    return _to_matrix(q)


def _to_matrix(q):
    # contiguous components written into one array: nested stacks of strided columns took
    # 8 ms at 100k rotors, this 5 ms (the same values)
    w, x, y, z = np.ascontiguousarray(np.moveaxis(q, -1, 0))
    out = np.empty(w.shape + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - w * z)
    out[..., 0, 2] = 2 * (x * z + w * y)
    out[..., 1, 0] = 2 * (x * y + w * z)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - w * x)
    out[..., 2, 0] = 2 * (x * z - w * y)
    out[..., 2, 1] = 2 * (y * z + w * x)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def from_axis_angle(axis: ArrayLike, degrees: float) -> np.ndarray:
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


def from_rotation_vectors(w: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4) of rotations by the vectors ``w`` (n, 3): angle ``|w|``
    (radians) about ``w``'s direction, ``exp(w / 2)``.

    Examples
    --------
    >>> q = from_rotation_vectors(np.array([[0, 0, np.pi / 2]]))
    >>> np.round(rotate(q, np.array([1., 0, 0])), 12)
    array([[0., 1., 0.]])
    """
    w = np.asarray(w, dtype=float)
    angle = np.linalg.norm(w, axis=1)
    half = 0.5 * angle
    # sin(h) / (2 h) -> 1/2 at 0; the series is exact to rounding below 1e-4 radians
    scale = np.where(angle > 1e-4, np.sin(half) / np.where(angle > 0, angle, 1.0),
                     0.5 - angle * angle / 48.0)
    return np.column_stack([np.cos(half), scale[:, None] * w])


def normalize(q: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """Scale quaternions to unit length; rows too short to normalize take ``fallback``.

    Parameters
    ----------
    q, fallback : (n, 4) float arrays
    """
    q, fallback = np.asarray(q, dtype=float), np.asarray(fallback, dtype=float)
    if splits(len(q)) and fallback.shape == q.shape:
        return fill(_normalize, np.empty(q.shape), q, fallback)
    return _normalize(q, fallback)


def _normalize(q, fallback):
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    ok = norm[:, 0] > 1e-300
    if ok.all():  # the usual case, without the masked gathers and scatter
        return q / norm
    out = np.array(fallback, dtype=float, copy=True)
    out[ok] = q[ok] / norm[ok]
    return out


def from_matrix(M: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4) of rotation matrices (n, 3, 3), with ``w >= 0``.

    Uses the largest of the four squared components to divide by (Shepperd's method), so
    every rotation, including half turns, converts accurately.
    """
    m = np.asarray(M, dtype=float)
    tr = np.trace(m, axis1=1, axis2=2)
    d = np.stack([tr, m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]], axis=1)
    k = np.argmax(np.column_stack([tr, 2 * d[:, 1:] - tr[:, None]]), axis=1)
    q = np.empty((len(m), 4))
    r = np.sqrt(np.maximum(1 + np.choose(k, [tr, 2 * d[:, 1] - tr, 2 * d[:, 2] - tr,
                                             2 * d[:, 3] - tr]), 0)) / 2
    s = 0.25 / r
    a = m[:, 2, 1] - m[:, 1, 2]
    b = m[:, 0, 2] - m[:, 2, 0]
    c = m[:, 1, 0] - m[:, 0, 1]
    xy, xz, yz = m[:, 0, 1] + m[:, 1, 0], m[:, 0, 2] + m[:, 2, 0], m[:, 1, 2] + m[:, 2, 1]
    q[k == 0] = np.column_stack([r, a * s, b * s, c * s])[k == 0]
    q[k == 1] = np.column_stack([a * s, r, xy * s, xz * s])[k == 1]
    q[k == 2] = np.column_stack([b * s, xy * s, r, yz * s])[k == 2]
    q[k == 3] = np.column_stack([c * s, xz * s, yz * s, r])[k == 3]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def align_hemisphere(q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Flip the sign of rows of ``q`` that point away from ``reference`` (same rotation)."""
    if splits(len(q)):
        return fill(_align, np.empty(np.shape(q)), q, reference)
    return _align(q, reference)


def _align(q, reference):
    return q * np.where(np.einsum("ij,ij->i", q, reference) < 0, -1.0, 1.0)[:, None]
