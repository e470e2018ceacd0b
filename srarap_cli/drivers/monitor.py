"""What every driver shares: the log, the callback, the non-finite check, the stopping rules."""
import time

import numpy as np

from ..errors import NumericalError


class Monitor:
    """Records accepted iterates and decides when to stop.

    Parameters
    ----------
    max_iter : int, steps at most
    tol : float, converged when ``|E_k - E_{k-1}| <= tol * |E_{k-1}|`` and no vertex moved
        more than ``sqrt(tol) * scale`` in that step (an accelerated step can change the
        shape a lot while the energy barely changes)
    time_limit : float or None, stop (not converged) after this many seconds
    callback : callable(dict) or None, called with each log row
    energy_floor : float, smallest ``|E_{k-1}|`` the relative change divides by
    scale : float, the mesh's size (bounding-box diagonal)

    Attributes
    ----------
    log : list of dict, one row per recorded iterate (keys ``solve_log.LOG_FIELDS``)
    converged : bool
    iterations : int, steps recorded after the start
    """

    def __init__(self, *, max_iter, tol, time_limit=None, callback=None, energy_floor=0.0,
                 scale=float("inf")):
        self.max_iter, self.tol, self.time_limit = max_iter, tol, time_limit
        self.move_tol = np.sqrt(max(tol, 0.0)) * scale
        self.callback, self.energy_floor = callback, energy_floor
        self.log = []
        self.converged = False
        self.start = time.perf_counter()

    @property
    def iterations(self):
        return max(len(self.log) - 1, 0)

    def record(self, state, previous=None, kind=None):
        """Log ``state`` (``previous``: the iterate it came from, None for the start;
        ``kind``: how the driver made it, default ``start`` or ``plain``); returns True
        when the solve should stop."""
        total = state.total
        if not np.isfinite(total):
            raise NumericalError(f"energy became non-finite at iteration {len(self.log)}")
        if previous is None:
            rel, move = float("nan"), 0.0
        else:
            last = self.log[-1]["total"]
            rel = abs(total - last) / max(abs(last), self.energy_floor)
            d = state.positions - previous.positions
            move = float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d), initial=0.0)))
        row = {"iteration": len(self.log), "membrane": state.membrane,
               "bending": state.bending, "total": total, "rel_change": rel,
               "max_move": move, "seconds": time.perf_counter() - self.start,
               "step": kind or ("start" if previous is None else "plain")}
        self.log.append(row)
        if self.callback is not None:
            self.callback(row)
        if previous is None:
            return self.max_iter <= 0
        if rel <= self.tol and move <= self.move_tol:
            self.converged = True
            return True
        timed_out = self.time_limit is not None and row["seconds"] >= self.time_limit
        return timed_out or self.iterations >= self.max_iter
