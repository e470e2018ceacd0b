"""The rotation each handle group undergoes, from its rest and target positions."""

import numpy as np
from scipy.sparse import csgraph, csr_matrix

from .quaternion import from_matrix


def group_rotors(rest: np.ndarray, targets: np.ndarray, labels: np.ndarray, n_groups: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The rotation each handle group undergoes, as a rotor per constrained vertex.

    Least-squares rotation (Kabsch) from each group's rest points to its targets: exact for
    a rigidly moved group. Groups whose rest points are collinear do not fix a rotation;
    they are flagged and left to the caller.

    Parameters
    ----------
    rest, targets : (k, 3) float arrays
    labels : (k,) int array in [0, n_groups)
    n_groups : int

    Returns
    -------
    rotors : (k, 4) float array
    determined : (k,) bool array

    Examples
    --------
    >>> rest = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> R, ok = group_rotors(rest, rest[:, [1, 0, 2]] * [-1, 1, 1], np.zeros(3, int), 1)
    >>> np.allclose(R[0], [np.sqrt(0.5), 0, 0, np.sqrt(0.5)]), bool(ok.all())
    (True, True)
    """
    count = np.bincount(labels, minlength=n_groups).astype(float)
    safe = np.maximum(count, 1)[:, None]
    x = rest - (label_sum(rest, labels, n_groups) / safe)[labels]
    y = targets - (label_sum(targets, labels, n_groups) / safe)[labels]
    H = label_sum((x[:, :, None] * y[:, None, :]).reshape(-1, 9), labels, n_groups)
    C = label_sum((x[:, :, None] * x[:, None, :]).reshape(-1, 9), labels, n_groups)
    finite = np.isfinite(H).all(axis=1) & np.isfinite(C).all(axis=1)
    H[~finite] = C[~finite] = 0.0  # overflow: no rotation; the solve reports the overflow
    U, _, Vt = np.linalg.svd(H.reshape(-1, 3, 3))
    flip = np.sign(np.linalg.det(Vt.transpose(0, 2, 1) @ U.transpose(0, 2, 1)))
    D = np.zeros((n_groups, 3, 3))
    D[:, 0, 0] = D[:, 1, 1] = 1
    D[:, 2, 2] = np.where(flip < 0, -1.0, 1.0)
    rot = Vt.transpose(0, 2, 1) @ D @ U.transpose(0, 2, 1)
    spread = np.linalg.svd(C.reshape(-1, 3, 3), compute_uv=False)
    determined = finite & (spread[:, 1] > 1e-12 * np.maximum(spread[:, 0], 1e-300))
    return from_matrix(rot)[labels], determined[labels]


def label_sum(values: np.ndarray, labels: np.ndarray, n_groups: int) -> np.ndarray:
    """Per-label sums of the rows of ``values`` (k, c): (n_groups, c)."""
    return np.stack([np.bincount(labels, weights=values[:, c], minlength=n_groups)
                     for c in range(values.shape[1])], axis=1)


def connected_groups(adjacency: csr_matrix, ids: np.ndarray) -> np.ndarray:
    """Handle groups when none are given: the connected patches the vertices ``ids`` form
    on the mesh (edges between two of them).

    Parameters
    ----------
    adjacency : (n, n) sparse matrix, nonzero (one direction is enough) where vertices share
        an edge
    ids : (k,) int array

    Returns
    -------
    (k,) int array, the group of each of ``ids``

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> A = sp.csr_matrix(np.array([[0, 1, 0, 0], [1, 0, 1, 0], [0, 1, 0, 1], [0, 0, 1, 0]]))
    >>> connected_groups(A, np.array([0, 1, 3])).tolist()
    [0, 0, 1]
    """
    sub = adjacency[ids][:, ids]
    return csgraph.connected_components(sub, directed=False)[1].astype(np.int64)
