"""Warm start: the caller's positions and rotors (a previous solve, the previous frame),
moved to follow the handles' change since then.

Moving only the constrained vertices to their new targets puts a kink at every handle's
boundary: a tube twisted 3 degrees further from its converged 30-degree pose started at 1.39x
the final energy and took 17 iterations to the stop, against 11 from the cold (harmonic)
start. Two candidates are made and the one of lower energy kept:

- each handle group's rotation since the previous state (its best fit from the previous
  positions of its vertices to their targets) spread harmonically, as the cold start spreads
  the rest-to-target rotations, and composed with the previous rotors;
- the previous rotors turned by their first-order response to the move
  (:mod:`..linear_response`): from a converged state the error left is of the order of the
  move squared. After a 1% change of every target (scaled by 1.01) the first candidate began
  2e-5 to 2e-3 above the minimum (sample bar, cylinder, Max bust, Spot) and the solves took
  5 / 9 / 9 / 19 iterations; from the second, 3 each (the stopping test's window).

The positions of each follow from one global step. When the targets did not change, the
start is the previous state after one more global step. The response is that of the energy's
minimum: for the paper's own system (``sr-linear``), whose fixed point sits 1.3% to 5% above
it, the lower-energy start was the farther one (Spot scaled by 1.01: 27 iterations, against
26 with the rotations only), so that method keeps the first candidate alone.
"""

import numpy as np

from ..quaternion import from_rotation_vectors, multiply, normalize
from ..state import State
from ..step import LocalGlobalStep
from .harmonic import spread_handle_rotors


def warm_start(step: LocalGlobalStep, initial: tuple[np.ndarray, np.ndarray]) -> State:
    """Start from ``initial = (positions (n, 3), rotors (n, 4))``, a solved state, moved by
    the handles' change: the lower-energy of the two candidates above.

    Returns
    -------
    State
    """
    P, R = _arrays(initial)
    d = step.deformer
    best = extrapolated_start(step, (P, R))
    moved = step.fixed_targets - P[d.fixed]
    if not (moved.any() and d.local_step.near_minimum):
        return best
    w = d.linear_response.rotations(P, R, moved)
    if w is None:
        return best
    turned = normalize(multiply(from_rotation_vectors(w), R), R)
    predicted = step.state(step.positions(turned), turned)
    return predicted if predicted.total < best.total else best


def extrapolated_start(step: LocalGlobalStep,
                       initial: tuple[np.ndarray, np.ndarray]) -> State:
    """Start from ``initial = (positions (n, 3), rotors (n, 4))`` with only the handles'
    rotations since then spread (the first candidate above): for a state that already
    follows the targets to first order, such as an animation's last frames carried on at
    their pace, where the response would cost more than it saves (5k-vertex tube turned 3
    degrees a frame: 21 frames/s without it, 10.5 with, the same 3 iterations a frame).

    Returns
    -------
    State
    """
    P, R = _arrays(initial)
    spread = normalize(multiply(spread_handle_rotors(step, P), R), R)
    return step.state(step.positions(spread), spread)


def _arrays(initial):
    if initial is None:
        raise ValueError("a warm start needs initial=(positions, rotors)")
    return np.asarray(initial[0], dtype=float), np.asarray(initial[1], dtype=float)
