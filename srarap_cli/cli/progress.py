"""A one-line progress display for long solves, on a terminal only."""
import sys
import time
from typing import Any

#: Seconds before the line appears (short runs stay silent) and between redraws.
DELAY, EVERY = 2.0, 0.2


class SolveProgress:
    """Callback for a solve's log rows: iteration, energy, relative change, elapsed time.

    Shown on stderr when it is a terminal, once the solve has run for :data:`DELAY` seconds;
    ``close`` clears the line so the summary that follows starts clean.
    """

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self.start = time.perf_counter()
        self.last = 0.0
        self.shown = False

    def __call__(self, row: dict[str, Any]) -> None:
        if not self.enabled:
            return
        now = time.perf_counter() - self.start
        if now < DELAY or now - self.last < EVERY:
            return
        self.last, self.shown = now, True
        sys.stderr.write(f"\riteration {row['iteration']}  energy {row['total']:.6g}  "
                         f"change {row['rel_change']:.2g}  {now:.1f} s ")
        sys.stderr.flush()

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()
