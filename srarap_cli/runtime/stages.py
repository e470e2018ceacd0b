"""A run's stages said as each one ends: ``-v`` prints a stage's line then, not after the
solve (a CI log of a long run shows where it is, and a stage that hangs is the one after the
last line). The stages announce themselves through :func:`ended`; a command listens with
:func:`heard_by`, for its own thread and those it starts (their contexts are copied)."""
import contextlib
import contextvars
from collections.abc import Callable, Iterator

_LISTENER: contextvars.ContextVar[Callable[[str, float], None] | None] = \
    contextvars.ContextVar("srarap_stage_listener", default=None)


def ended(name: str, seconds: float) -> float:
    """Say that the stage ``name`` ended after ``seconds`` to whoever listens; returns
    ``seconds`` (so a stage's timing is kept and said in one expression)."""
    listener = _LISTENER.get()
    if listener is not None:
        listener(name, seconds)
    return seconds


@contextlib.contextmanager
def heard_by(listener: Callable[[str, float], None] | None) -> Iterator[None]:
    """Within the block, :func:`ended` calls ``listener(name, seconds)`` (None: nobody)."""
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)
