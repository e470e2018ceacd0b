"""Carry rotors from the coarse mesh to the fine mesh (paper eq 7.4) and name the rotors
of handle vertices the coarse mesh left out (each group's own rotation: not the paper's
section 6.2, which solves constrained rotors from their cells, see ``local_step``)."""
import numpy as np

from ..group_rotations import label_sum
from ..quaternion import IDENTITY, align_hemisphere, normalize
from .dirichlet import DirichletSolver


def spread_rotors(solver: DirichletSolver, known_rotors: np.ndarray) -> np.ndarray:
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


def orient_group_rotors(rotors: np.ndarray, determined: np.ndarray, labels: np.ndarray, n_groups: int,
                        coarse_slots: np.ndarray, coarse_rotors: np.ndarray) -> np.ndarray:
    """Rotors for all constrained vertices, on the hemisphere of the coarse solution.

    Each group's rotor is flipped toward the sum of the coarse rotors of its vertices that
    are coarse vertices; groups whose rotation is not determined take that sum, normalized.

    Parameters
    ----------
    rotors, determined : from :func:`~srarap_cli.solver.group_rotations.group_rotors`, (k, 4), (k,)
    labels : (k,) int array
    n_groups : int
    coarse_slots : (c,) int array, which constrained vertices are coarse vertices
    coarse_rotors : (c, 4) float array, their rotors from the coarse solve
    """
    mean = label_sum(coarse_rotors, labels[coarse_slots], n_groups)[labels]
    reference = np.where(np.linalg.norm(mean, axis=1, keepdims=True) > 0, mean, IDENTITY)
    out = align_hemisphere(rotors, reference)
    out[~determined] = normalize(reference[~determined],
                                 np.broadcast_to(IDENTITY, reference[~determined].shape))
    return out
