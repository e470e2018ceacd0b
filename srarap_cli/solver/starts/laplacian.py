"""Laplacian editing: identity rotors and one Poisson solve (the paper's and today's start)."""
import numpy as np

from ..quaternion import IDENTITY


def laplacian_start(step, initial=None):
    """Identity rotors everywhere, positions from one global step.

    Parameters
    ----------
    step : LocalGlobalStep
    initial : ignored

    Returns
    -------
    State
    """
    R = np.tile(IDENTITY, (len(step.deformer.V), 1))
    return step.state(step.positions(R), R)
