"""Laplacian editing: identity rotors and one Poisson solve (the paper's and today's start)."""
import numpy as np

from ..quaternion import IDENTITY
from ..state import State
from ..step import LocalGlobalStep


def laplacian_start(step: LocalGlobalStep, initial: object = None) -> State:
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
