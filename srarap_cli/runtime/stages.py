"""A run's stages, said as each one begins and ends: ``-v`` prints a stage's line as it ends,
not after the solve (a CI log of a long run shows where it is, and a stage that hangs is the
one after the last line), and a heartbeat names the stages still running (:func:`running`)
while none of them says anything. The stages announce themselves through :func:`begun` and
:func:`ended`; a command listens with :func:`heard_by`, for its own thread and those it
starts (their contexts are copied).

A multiresolution solve nests: its coarse level is a solve of its own, with stages of the
same names. Inside :func:`deeper` a stage is named with its level (``coarse level 1:
multires: simplify``), in the ``-v`` lines and the heartbeat alike.
"""
import contextlib
import contextvars
import threading
import time
from collections.abc import Callable, Iterator

_LISTENER: contextvars.ContextVar[Callable[[str, float], None] | None] = \
    contextvars.ContextVar("srarap_stage_listener", default=None)
_DEPTH: contextvars.ContextVar[int] = contextvars.ContextVar("srarap_stage_depth", default=0)
#: the stages running now, in the order they began: (name with its level, start)
_RUNNING: list[tuple[str, float]] = []
_lock = threading.Lock()


def _named(name: str) -> str:
    depth = _DEPTH.get()
    return f"coarse level {depth}: {name}" if depth else name


def begun(name: str) -> None:
    """Say that the stage ``name`` begins (a heartbeat names it until :func:`ended`)."""
    with _lock:
        _RUNNING.append((_named(name), time.perf_counter()))


def ended(name: str, seconds: float) -> float:
    """Say that the stage ``name`` ended after ``seconds`` to whoever listens; returns
    ``seconds`` (so a stage's timing is kept and said in one expression)."""
    label = _named(name)
    with _lock:
        for k in range(len(_RUNNING) - 1, -1, -1):
            if _RUNNING[k][0] == label:
                del _RUNNING[k]
                break
    listener = _LISTENER.get()
    if listener is not None:
        listener(label, seconds)
    return seconds


def forget() -> None:
    """Forget every stage said to run (a job that failed inside one never ended it)."""
    with _lock:
        _RUNNING.clear()


def running() -> list[tuple[str, float]]:
    """The stages running now (begun, not ended), each with its seconds so far, in the order
    they began."""
    now = time.perf_counter()
    with _lock:
        return [(label, now - start) for label, start in _RUNNING]


@contextlib.contextmanager
def deeper() -> Iterator[None]:
    """Within the block, stages are a coarser level's (named ``coarse level N: ...``)."""
    token = _DEPTH.set(_DEPTH.get() + 1)
    try:
        yield
    finally:
        _DEPTH.reset(token)


@contextlib.contextmanager
def heard_by(listener: Callable[[str, float], None] | None) -> Iterator[None]:
    """Within the block, :func:`ended` calls ``listener(name, seconds)`` (None: nobody)."""
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)
