"""Warm start: the caller's positions and rotors (a previous solve, the previous frame)."""
import numpy as np


def warm_start(step, initial):
    """Start from ``initial = (positions (n, 3), rotors (n, 4))``, constrained vertices moved
    to their targets.

    Returns
    -------
    State
    """
    if initial is None:
        raise ValueError("the warm start needs initial=(positions, rotors)")
    P = np.array(initial[0], dtype=float)
    R = np.array(initial[1], dtype=float)
    P[step.deformer.fixed] = step.fixed_targets
    return step.state(P, R)
