from collections.abc import Callable

from ..state import State
from .monitor import Monitor

"""The plain fixed-point iteration ``x_{k+1} = G(x_k)``: local step, global step, repeat."""


def plain_iteration(step: Callable[[State], State], state: State, monitor: Monitor) -> State:
    """Iterate ``step`` until ``monitor`` says stop.

    Parameters
    ----------
    step : callable State -> State
    state : State, the start
    monitor : Monitor

    Returns
    -------
    State, the last iterate
    """
    stop = monitor.record(state)
    while not stop:
        new = step(state)
        stop = monitor.record(new, state)
        state = new
    return state
