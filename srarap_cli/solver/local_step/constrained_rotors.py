"""Paper section 6.2: the rotors of constrained vertices, each from its own 4x4 system.

A constrained vertex has no unknown position, but its cell still has a rotor. The paper takes
it from the vertex's own row of the rotor system with the neighbours' rotors held at their
previous values, before the one sparse solve for the free rotors (which then sees these
rotors as known).
"""
import numpy as np

from ..quaternion import normalize


def constrained_rotors(D: np.ndarray, neighbour_pull: np.ndarray, feedback_pull: np.ndarray,
                       R_prev: np.ndarray) -> np.ndarray:
    """Solve ``D_i R_i = neighbour_pull_i + feedback_pull_i`` per constrained cell, normalized.

    Parameters
    ----------
    D : (k, 4, 4) float array, the cells' diagonal blocks ``sigma_i M_i + tau_i I``
    neighbour_pull : (k, 4) float array, ``sum_j omega_ij R_j^prev``
    feedback_pull : (k, 4) float array, ``phi_i R_i^prev`` (section 6.3)
    R_prev : (k, 4) float array, previous rotors (hemisphere of the result)

    Returns
    -------
    (k, 4) float array of unit quaternions

    Examples
    --------
    >>> D = np.eye(4)[None] * 2.0
    >>> constrained_rotors(D, np.array([[1.0, 0, 0, 0]]), np.zeros((1, 4)), np.eye(4)[:1])
    array([[1., 0., 0., 0.]])
    """
    rhs = neighbour_pull + feedback_pull
    return normalize(np.linalg.solve(D, rhs[..., None])[..., 0], R_prev)
