"""Carry rotors from the coarse mesh to the fine mesh (paper eq 7.4) and name the rotors
of handle vertices the coarse mesh left out (each group's own rotation: not the paper's
section 6.2, which solves constrained rotors from their cells, see ``local_step``)."""
import numpy as np

from ..quaternion import IDENTITY, align_hemisphere, from_matrix, normalize


def spread_rotors(solver, known_rotors):
    """Harmonic rotor field: ``L R = 0`` with ``R = known_rotors`` at ``solver.known``,
    four right-hand sides, then normalized.

    Parameters
    ----------
    solver : DirichletSolver of the fine cotangent Laplacian
    known_rotors : (k, 4) float array, unit quaternions on one hemisphere per region

    Returns
    -------
    (n, 4) float array of unit quaternions

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> from .dirichlet import DirichletSolver
    >>> K = sp.csr_matrix(np.array([[1., -1, 0], [-1, 2, -1], [0, -1, 1]]))
    >>> R = spread_rotors(DirichletSolver(K, np.array([0, 2])), np.tile([0.6, 0.8, 0, 0], (2, 1)))
    >>> np.allclose(R, [0.6, 0.8, 0, 0])
    True
    """
    R = solver.solve(known_rotors)
    return normalize(R, np.broadcast_to(IDENTITY, R.shape))


def group_rotors(rest, targets, labels, n_groups):
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
    x = rest - (_label_sum(rest, labels, n_groups) / safe)[labels]
    y = targets - (_label_sum(targets, labels, n_groups) / safe)[labels]
    H = _label_sum((x[:, :, None] * y[:, None, :]).reshape(-1, 9), labels, n_groups)
    U, _, Vt = np.linalg.svd(H.reshape(-1, 3, 3))
    flip = np.sign(np.linalg.det(Vt.transpose(0, 2, 1) @ U.transpose(0, 2, 1)))
    D = np.zeros((n_groups, 3, 3))
    D[:, 0, 0] = D[:, 1, 1] = 1
    D[:, 2, 2] = np.where(flip < 0, -1.0, 1.0)
    rot = Vt.transpose(0, 2, 1) @ D @ U.transpose(0, 2, 1)
    spread = np.linalg.svd(_label_sum((x[:, :, None] * x[:, None, :]).reshape(-1, 9), labels,
                                      n_groups).reshape(-1, 3, 3), compute_uv=False)
    determined = spread[:, 1] > 1e-12 * np.maximum(spread[:, 0], 1e-300)
    return from_matrix(rot)[labels], determined[labels]


def _label_sum(values, labels, n_groups):
    return np.stack([np.bincount(labels, weights=values[:, c], minlength=n_groups)
                     for c in range(values.shape[1])], axis=1)


def orient_group_rotors(rotors, determined, labels, n_groups, coarse_slots, coarse_rotors):
    """Rotors for all constrained vertices, on the hemisphere of the coarse solution.

    Each group's rotor is flipped toward the sum of the coarse rotors of its vertices that
    are coarse vertices; groups whose rotation is not determined take that sum, normalized.

    Parameters
    ----------
    rotors, determined : from :func:`group_rotors`, (k, 4) and (k,)
    labels : (k,) int array
    n_groups : int
    coarse_slots : (c,) int array, which constrained vertices are coarse vertices
    coarse_rotors : (c, 4) float array, their rotors from the coarse solve
    """
    mean = _label_sum(coarse_rotors, labels[coarse_slots], n_groups)[labels]
    reference = np.where(np.linalg.norm(mean, axis=1, keepdims=True) > 0, mean, IDENTITY)
    out = align_hemisphere(rotors, reference)
    out[~determined] = normalize(reference[~determined],
                                 np.broadcast_to(IDENTITY, reference[~determined].shape))
    return out
