"""Progress of a long run on stderr: a line redrawn in place on a terminal, a line every
:data:`LOG_EVERY` seconds elsewhere (a CI log, ``make``, a file), so that a long run shows life
and a hang can be told from work; ``-q`` silences both. Between a solve's iterations the
line is theirs; in every other long stage (reading, simplifying, setting up, a coarse
level's solve) a heartbeat names the stages running and their levels
(:func:`srarap_cli.runtime.stages.running`)."""
import contextlib
import os
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any

from ..runtime import stages

#: Seconds before the terminal's line appears (short runs stay silent) and between redraws.
DELAY, EVERY = 2.0, 0.2
#: Seconds between lines on a stderr that is not a terminal (``SRARAP_PROGRESS_EVERY``)
LOG_EVERY = 10.0
ENV = "SRARAP_PROGRESS_EVERY"


def log_interval() -> float:
    """Seconds between progress lines in a log: ``$SRARAP_PROGRESS_EVERY`` where it is a
    positive number, else :data:`LOG_EVERY`."""
    try:
        value = float(os.environ.get(ENV, ""))
    except ValueError:
        return LOG_EVERY
    return value if value > 0 else LOG_EVERY


class SolveProgress:
    """Callback for a solve's log rows: the level (a multiresolution solve's coarse mesh or
    full resolution), iteration, energy, relative change, elapsed time.

    Parameters
    ----------
    enabled : bool, show anything at all (not ``-q``)
    terminal : bool, stderr is a terminal (default: asked of it)
    """

    def __init__(self, enabled: bool, terminal: bool | None = None, prefix: str = "") -> None:
        self.enabled = enabled
        self.prefix = prefix
        self.terminal = sys.stderr.isatty() if terminal is None else terminal
        self.every = EVERY if self.terminal else log_interval()
        self.delay = DELAY if self.terminal else self.every
        self.start = time.perf_counter()
        self.last = 0.0
        self.shown = False
        self.levels = False  # a row named its level: the solve has a coarse mesh
        self.last_row = -float("inf")  # when the solve last sent a row (they say its state)
        self.row_shown = -float("inf")  # when a row was last shown: a heartbeat never delays one
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if enabled:
            self._thread = threading.Thread(target=self._beat, name="srarap-heartbeat",
                                            daemon=True)
            self._thread.start()

    def _beat(self) -> None:
        """While no row said anything for an interval, name the stages running."""
        while not self._stop.wait(min(self.every, 1.0) / 4):
            now = time.perf_counter() - self.start
            if now < self.delay or now - max(self.last, self.last_row) < self.every:
                continue
            busy = stages.running()
            if busy and not self._stop.is_set():
                self._show("; ".join(f"{name} {seconds:.1f} s" for name, seconds in busy)
                           + f"  ({now:.1f} s in all)")

    def __call__(self, row: dict[str, Any]) -> None:
        if not self.enabled:
            return
        self.levels = self.levels or "level" in row
        now = self.last_row = time.perf_counter() - self.start
        if now < self.delay or now - self.row_shown < self.every:
            return
        self.row_shown = now
        level = f"{row.get('level', 'full resolution')}, " if self.levels else ""
        self._show(f"{level}iteration {row['iteration']}  energy {row['total']:.6g}  "
                   f"change {row['rel_change']:.2g}  {now:.1f} s")

    def _show(self, text: str) -> None:
        # on a terminal the line is cleared first: a shorter one left the longer one's tail;
        # the time it was stamped at is the time it is written (one writer at a time)
        with self._lock:
            self.last, self.shown = time.perf_counter() - self.start, True
            sys.stderr.write(f"\r\033[K{self.prefix}{text}" if self.terminal
                             else f"srarap: progress: {self.prefix}{text}\n")
            sys.stderr.flush()

    def say(self, line: str) -> None:
        """Print ``line`` on stderr, on a terminal over the progress line (redrawn at the next
        row), so that the two never share a line."""
        with self._lock:  # never inside a heartbeat's line
            sys.stderr.write(("\r\033[K" if self.shown and self.terminal else "") + line + "\n")
            sys.stderr.flush()

    def stage(self, name: str, seconds: float) -> None:
        """A stage's ``-v`` line, as it ends (see :mod:`srarap_cli.runtime.stages`)."""
        self.say(f"srarap: stage: {name} {seconds:.2f} s")

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:  # nothing of it may reach a stream its caller closes
            self._thread.join(timeout=5.0)
        if self.shown and self.terminal:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


class FrameProgress(SolveProgress):
    """Progress of an animation, frame by frame: frames done, rate and time left, redrawn on
    a terminal, a line every :func:`log_interval` seconds in a log; ``-q`` silences it."""

    def __init__(self, enabled: bool, terminal: bool | None = None) -> None:
        super().__init__(enabled, terminal)
        if self.terminal:  # a frame is a unit a user waits for: shown from the first one
            self.delay = 0.0

    def frame(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        now = time.perf_counter() - self.start
        if now < self.delay or (done < total and now - self.last < self.every):
            return  # a short run says nothing; a long one's last frame is said
        self.last, self.shown = now, True
        rate = done / max(now, 1e-9)
        self._show(f"frame {done}/{total}  {rate:.2f} frames/s  "
                   f"ETA {(total - done) / max(rate, 1e-9):.0f} s  {now:.1f} s")


@contextlib.contextmanager
def job_heartbeat(name: str) -> Iterator[None]:
    """A batch job's heartbeat in the log of the process that runs it (the batch, a worker
    process, a Dask worker): its stages named every :func:`log_interval` seconds while it
    runs long (lines, never a redrawn one: the batch's own lines share the stream)."""
    beat = SolveProgress(enabled=True, terminal=False, prefix=f"job {name!r}: ")
    try:
        yield
    finally:
        beat.close()
