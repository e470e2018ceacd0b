"""What every driver shares: the log, the callback, the non-finite check, the stopping rules.

The energy test averages the relative change over the last :data:`WINDOW` iterates: with
acceleration the energy does not fall smoothly, and one accepted step that happens to change
it by little said nothing about the steps around it (a refine run on the 46k Spot stopped
0.08% above the minimum on one such step while its neighbours still gained 1e-5 each).
The test waits for a full window: a warm start (the previous frame of an animation) whose first
step changed the energy by less than ``tol`` used to stop after that one step, and across a
sequence those early stops added up (a tube twisted 3 degrees a frame drifted to 2.7e-4 of
the diagonal from the tight solve after 40 frames, against 2.4e-5 when three steps are
required; a warm start from a converged result now stops after three).
An energy below ``tol * EXACT`` times the rest shape's scale ``sum c
|q|^2`` is converged at once: the minimum is not below zero, so at most that much is left to
gain (vertices within about ``sqrt(tol * EXACT)`` of the edge lengths of the answer), while the
relative changes of an energy near rounding level are noise that may never settle.
That energy has a floor, though: the rotors come out of their solves with errors of about
1e-9, so an exactly rigid answer keeps a bending energy of 1e-17 (a 106-vertex tube) to 1e-14
(Spot) of the scale, more on larger meshes, above ``tol * EXACT`` for a tol below about 1e-8;
such a solve never stopped (a rigid motion asked to tol 1e-12 ran its 1000 iterations, exact
from the first). So a solve whose last WINDOW steps each moved no vertex by more than its
rounding is converged too: its iterate no longer changes, and further steps only stir the
rounding. That rounding grows with the mesh (the Poisson solve's conditioning): a rigid
answer's steps moved vertices by 1 unit of double rounding of the mesh's size on the
106-vertex tube, 5 on Spot, 60 on the 100k bar and 94 on the 1.2M bar, so a step counts as
still below :data:`STILL` units or n/25 on n vertices, whichever is more. Not much more: a
converging solve to tol 1e-12 (the sample bar's twist) still moves vertices by 1e-10 of the
size a step while it gains 1e-11 of its energy, and a bound there stopped it 12 steps
early, 2.5e-10 of the size short. A tol of 0 (a fixed budget) runs its budget.
"""
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ...runtime.errors import NumericalError
from ..state import State
from ..stop import StopReason

#: iterates whose mean relative energy change is compared with ``tol``
WINDOW = 3
#: an energy below ``tol * EXACT`` of the rest shape's scale is an exact answer
EXACT = 1e-6
#: relative changes divide by at least this much of the rest shape's scale
FLOOR = 1e-14
#: steps that move no vertex by more than this many units of double rounding of the mesh's
#: size (or n/25 on n vertices, where that is more) leave it as it is, but for rounding
STILL = 64
EPS = float(np.finfo(float).eps)


def recent_changes(log: list[dict[str, Any]], key: str = "rel_change") -> list[float]:
    """Relative energy changes (or another column, ``key``) of the last WINDOW steps of
    ``log`` after its latest start row (``step`` ending in ``start``), oldest first; what the
    energy test averages."""
    changes: list[float] = []
    for row in reversed(log):
        if row["step"].endswith("start") or len(changes) == WINDOW:
            break
        changes.append(row[key])
    return changes[::-1]


class Monitor:
    """Records accepted iterates and decides when to stop.

    Parameters
    ----------
    max_iter : int, steps at most
    tol : float, converged when the relative energy changes ``|E_k - E_{k-1}| / |E_{k-1}|``
        of the last WINDOW steps average at most ``tol`` and the last step moved no vertex by
        more than ``sqrt(tol) * scale`` (an accelerated step can change the shape a lot while
        the energy barely changes); or when the energy is below ``tol * EXACT * energy_scale``;
        or (tol above 0) when the last WINDOW steps each moved no vertex by more than
        ``max(STILL, n / 25) * EPS * scale`` on n vertices
    time_limit : float or None, stop (not converged) after this many seconds
    callback : callable(dict) or None, called with each log row
    energy_scale : float, the rest shape's ``sum c |q|^2``; relative changes divide by at
        least ``1e-14`` of it
    scale : float, the mesh's size (bounding-box diagonal)

    Attributes
    ----------
    log : list of dict, one row per recorded iterate (keys ``solve_log.LOG_FIELDS``); the
        last row's ``stop`` holds the stop reason, the others' is empty
    reason : StopReason or None (still running)
    detail : str, which test kept an unconverged solve from stopping, with its numbers
    converged : bool
    iterations : int, steps recorded after the start
    """

    def __init__(self, *, max_iter: int, tol: float, time_limit: float | None = None,
                 callback: Callable[[dict], None] | None = None, energy_scale: float = 0.0,
                 scale: float = float("inf")) -> None:
        self.max_iter, self.tol, self.time_limit = max_iter, tol, time_limit
        self.move_tol = np.sqrt(max(tol, 0.0)) * scale
        self.still_unit = EPS * scale if tol > 0 and np.isfinite(scale) else -1.0
        self.still_tol = -1.0  # set at the start, from the mesh's vertex count
        self.callback = callback
        self.energy_floor = FLOOR * energy_scale
        self.exact_energy = max(tol, 0.0) * EXACT * energy_scale
        self.log: list[dict[str, Any]] = []
        self.reason: StopReason | None = None
        self.detail = ""
        self.start = time.perf_counter()

    @property
    def converged(self) -> bool:
        return self.reason is StopReason.CONVERGED

    @property
    def iterations(self) -> int:
        return max(len(self.log) - 1, 0)

    def record(self, state: State, previous: State | None = None, kind: str | None = None) -> bool:
        """Log ``state`` (``previous``: the iterate it came from, None for the start;
        ``kind``: how the driver made it, default ``start`` or ``plain``); returns True
        when the solve should stop."""
        total = state.total
        if not np.isfinite(total):
            raise NumericalError(f"energy became non-finite at iteration {len(self.log)}")
        if previous is None:
            rel, move = float("nan"), 0.0
            self.still_tol = max(STILL, len(state.positions) / 25) * self.still_unit
        else:
            last = self.log[-1]["total"]
            rel = abs(total - last) / max(abs(last), self.energy_floor)
            d = state.positions - previous.positions
            move = float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d), initial=0.0)))
        row = {"iteration": len(self.log), "membrane": state.membrane,
               "bending": state.bending, "total": total, "rel_change": rel,
               "max_move": move, "seconds": time.perf_counter() - self.start,
               "step": kind or ("start" if previous is None else "plain"), "stop": ""}
        self.log.append(row)
        self.reason = self._reason(previous is None, move, row["seconds"])
        if self.reason is not None:
            row["stop"] = self.reason.value
        if self.callback is not None:
            self.callback(dict(row))  # a copy: the caller's changes never reach the log
        return self.reason is not None

    def _reason(self, start, move, seconds):
        """The stop reason after the latest row, or None to go on."""
        if not start:
            changes = recent_changes(self.log)
            settled = len(changes) == WINDOW and sum(changes) <= WINDOW * self.tol
            exact = abs(self.log[-1]["total"]) < self.exact_energy
            if (settled or exact) and move <= self.move_tol:
                return StopReason.CONVERGED
            moves = recent_changes(self.log, "max_move")
            if len(moves) == WINDOW and max(moves) <= self.still_tol:
                return StopReason.CONVERGED
        if self.iterations >= self.max_iter:
            reason = StopReason.ITERATIONS_RUN if self.tol == 0 else StopReason.ITERATION_LIMIT
        elif not start and self.time_limit is not None and seconds >= self.time_limit:
            reason = StopReason.TIME_LIMIT
        else:
            return None
        self.detail = self._unsettled()
        return reason

    def _unsettled(self):
        """Which stopping test was still failing, with the numbers it compared."""
        changes = recent_changes(self.log)
        if not changes:
            return "no iteration ran"
        mean = sum(changes) / len(changes)
        if mean > self.tol:
            return (f"relative change {mean:.3g} per step over the last {len(changes)} > "
                    f"tol {self.tol:g}")
        if len(changes) < WINDOW:
            return f"only {len(changes)} of the {WINDOW} steps the energy test averages ran"
        return (f"relative change {mean:.3g} per step but the last step still moved a vertex "
                f"by {self.log[-1]['max_move']:.3g}")
