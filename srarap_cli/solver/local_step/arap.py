"""``arap``: classic as-rigid-as-possible (Sorkine & Alexa 2007), no bending term.

Each cell's rotation is the best fit of its deformed to its rest edges: the rotation closest
to ``S_i = sum_j c_ij p_ij q_ij^T``, found directly as a quaternion by
:func:`~srarap_cli.solver.closest_rotors.closest_rotors` (equal to the sign-corrected ``U V^T`` of
the SVD to rounding, flat one-rings included, and about twice as fast as libigl's
``fit_rotations`` followed by a matrix-to-quaternion conversion).
"""

import numpy as np

from ..closest_rotors import closest_rotors
from ..rest_edges import RestEdges


class ArapRotorStep:
    """Per-cell Procrustes fit. Parameters as the other steps; only the graph is used."""

    bending = False
    needs_stretch = False  # the rotation fit needs only S; the energy, only sum_i s_i
    near_minimum = True

    def __init__(self, edges: RestEdges, constrained: np.ndarray, alpha_area: float, feedback: float) -> None:
        """Nothing to precompute: each step fits rotations to the covariances alone."""

    def step(self, S: np.ndarray, s: np.ndarray | None, R_prev: np.ndarray,
             forcing: float = 0.0) -> np.ndarray:  # closed form: no forcing
        return closest_rotors(S, R_prev)
