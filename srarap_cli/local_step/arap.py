"""``arap``: classic as-rigid-as-possible (Sorkine & Alexa 2007), no bending term.

Each cell's rotation is the best fit of its deformed to its rest edges: the rotation closest
to ``S_i = sum_j c_ij p_ij q_ij^T`` (``U V^T`` of its SVD, sign-corrected), computed with
libigl's ``fit_rotations`` (the routine libigl's own ARAP uses; three to four times faster
than numpy's batched SVD here, and equal to it to 1e-14, flat one-rings included).
"""
import igl
import numpy as np

from ..quaternion import align_hemisphere, from_matrix


def closest_rotations(S):
    """Rotation matrices (n, 3, 3) maximizing ``trace(R^T S_i)`` for covariances S (n, 3, 3)."""
    n = len(S)
    stacked = np.ascontiguousarray(S.transpose(1, 0, 2).reshape(-1, 3))  # libigl's layout
    return np.asarray(igl.fit_rotations(stacked, False)).reshape(3, n, 3).transpose(1, 2, 0)


class ArapRotorStep:
    """Per-cell Procrustes fit. Parameters as the other steps; only the graph is used."""

    bending = False

    def __init__(self, edges, constrained, alpha_area, feedback):
        """Nothing to precompute: each step fits rotations to the covariances alone."""

    def step(self, S, s, R_prev):
        return align_hemisphere(from_matrix(closest_rotations(S)), R_prev)
