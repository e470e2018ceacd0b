"""The plain fixed-point iteration ``x_{k+1} = G(x_k)``: local step, global step, repeat."""
from collections.abc import Callable

from ..state import State
from .monitor import Monitor


def plain_iteration(step: Callable[[State], State], state: State, monitor: Monitor) -> State:
    """Iterate ``step`` until ``monitor`` says stop.

    Parameters
    ----------
    step : callable State -> State
    state : State, the start (released once it is left behind: :meth:`State.release`)
    monitor : Monitor

    Returns
    -------
    State, the last iterate
    """
    stop = monitor.record(state)
    while not stop:
        new = step(state)
        stop = monitor.record(new, state)
        state.release()
        state = new
    return state
