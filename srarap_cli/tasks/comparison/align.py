"""The rigid motion that brings one set of corresponding points closest to another (least
squares, Kabsch): for a golden exported from a pipeline that placed the mesh elsewhere."""
from typing import Any

import numpy as np

from ...io.mesh.mesh import Mesh


def rigid_motion(A: np.ndarray, B: np.ndarray) -> dict[str, Any]:
    """The rotation ``R`` and translation ``t`` minimizing ``sum |A_i - (R B_i + t)|^2``.

    Parameters
    ----------
    A, B : (n, 3) float arrays, point i of A corresponds to point i of B

    Returns
    -------
    dict with ``rotation`` ((3, 3) list, a proper rotation: no mirror), ``translation``
    ((3,) list, model units), ``angle`` (degrees) and ``axis`` ((3,) unit list; [0, 0, 1]
    for no rotation)

    Examples
    --------
    >>> A = np.array([[0., 0, 0], [1, 0, 0], [0, 2, 0], [0, 0, 3]])
    >>> B = A @ np.array([[0., -1, 0], [1, 0, 0], [0, 0, 1]]).T + [5, 0, 0]  # 90 degrees, moved
    >>> m = rigid_motion(A, B)
    >>> round(m["angle"], 9), [round(x, 9) + 0 for x in m["axis"]]
    (90.0, [0.0, 0.0, -1.0])
    >>> np.allclose(B @ np.array(m["rotation"]).T + m["translation"], A)
    True
    """
    A, B = np.asarray(A, float), np.asarray(B, float)
    ca, cb = A.mean(axis=0), B.mean(axis=0)
    U, _, Vt = np.linalg.svd((B - cb).T @ (A - ca))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0])
    R = Vt.T @ D @ U.T
    t = ca - R @ cb
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])  # 2 sin(angle) axis
    angle = float(np.degrees(np.arctan2(np.linalg.norm(w), np.trace(R) - 1)))
    if np.linalg.norm(w) > 1e-12:
        axis = w / np.linalg.norm(w)
    elif angle > 90:  # a half turn: the axis is the eigenvector of eigenvalue 1
        vals, vecs = np.linalg.eigh((R + R.T) / 2)
        axis = vecs[:, int(np.argmax(vals))]
    else:
        axis = np.array([0.0, 0.0, 1.0])
    return {"rotation": R.tolist(), "translation": t.tolist(), "angle": angle,
            "axis": axis.tolist()}


def moved(mesh: Mesh, motion: dict[str, Any]) -> Mesh:
    """``mesh`` moved by ``motion`` (as :func:`rigid_motion` gives it)."""
    return mesh.with_vertices(mesh.vertices @ np.asarray(motion["rotation"]).T
                              + motion["translation"])
