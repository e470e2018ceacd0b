"""SIGINT and SIGTERM at any moment: one line, the documented code, the truth about outputs.

Both signals are routed to exceptions (:class:`KeyboardInterrupt`, :class:`Terminated`) and
recorded, so that a signal some library swallowed on its way (an import that turned it into an
ImportError and was caught) is still reported. Compiled libraries are imported with the signals
held back (:func:`deferred`): pybind11 modules turn a signal during their initialization into
``ImportError: std::bad_cast``. The process ends through :func:`exit_now`, with the signals
blocked and without the interpreter's teardown: a background thread still inside a
factorization (multiresolution runs one beside the simplification) would otherwise crash the
finalizing interpreter, and a signal during the teardown would be lost or print a traceback.
"""
import contextlib
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any, NoReturn

from . import exit_codes, streams

SIGNALS = (signal.SIGINT, signal.SIGTERM)
#: the first of SIGINT/SIGTERM this process received (0: none)
RECEIVED = 0
#: whether this process is the ``srarap`` command (:func:`own`), not a library's host
OWNED = False
CODES = {signal.SIGINT: exit_codes.INTERRUPTED, signal.SIGTERM: exit_codes.TERMINATED}
WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


class Terminated(BaseException):
    """SIGTERM arrived; raised so that cleanup (temporary files) runs on the way out."""


#: set while :func:`_on_unraisable` runs: a signal's handler must not raise there
_IN_HOOK = False


def _on_signal(signum, frame):
    global RECEIVED
    RECEIVED = RECEIVED or signum
    if _IN_HOOK or _in_import_machinery(frame):
        # raised inside the import system, the exception could leave the import lock held
        # (a weakref callback that takes it) and is printed as "Exception ignored in"
        _send_again(signum)
        return
    if signum == signal.SIGINT:
        raise KeyboardInterrupt()
    raise Terminated()


def _in_import_machinery(frame) -> bool:
    return frame is not None and frame.f_code.co_filename.startswith("<frozen importlib")


def _send_again(signum: int) -> None:
    """The signal again to the main thread in a moment, from another thread: its handler then
    runs at the interpreter's next check, which is past the place it could not raise in (or
    it is sent again). Anything that tripped the handler from here, in this thread, would run
    it here at once."""
    threading.Thread(target=_send_later, args=(signum,), daemon=True).start()


def _send_later(signum: int) -> None:
    time.sleep(0.005)
    main = threading.main_thread().ident
    if main is not None:  # always, once the main thread started
        signal.pthread_kill(main, signum)


#: the hook that had been set before :func:`_route` (a test runner's), for everything else
_other_hook = sys.unraisablehook
_SIGNAL_OF = {KeyboardInterrupt: signal.SIGINT, Terminated: signal.SIGTERM}


def _on_unraisable(unraisable) -> None:
    """A signal's exception raised inside a finalizer or a weakref callback cannot leave it:
    Python printed "Exception ignored in" with a traceback and the signal was lost (the batch
    went on)."""
    global _IN_HOOK
    signum = _SIGNAL_OF.get(type(unraisable.exc_value))
    if signum is None or threading.current_thread() is not threading.main_thread():
        _other_hook(unraisable)
        return
    _IN_HOOK = True
    try:
        _send_again(signum)
    finally:
        _IN_HOOK = False


def own() -> None:
    """Take the signals for the ``srarap`` process (the console entry calls this first)."""
    global OWNED
    OWNED = True
    _route()


def _route() -> dict[int, Any]:
    """Route SIGINT and SIGTERM to exceptions (main thread only: signals go there); returns
    the handlers they replaced."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    global _other_hook
    if sys.unraisablehook is not _on_unraisable:
        _other_hook, sys.unraisablehook = sys.unraisablehook, _on_unraisable
    return {signum: signal.signal(signum, _on_signal) for signum in SIGNALS}


@contextlib.contextmanager
def routed() -> Iterator[None]:
    """SIGINT and SIGTERM routed to exceptions inside the block. In a process that hosts
    srarap (a test runner, a notebook, a service calling the command in-process), the host's
    handlers come back after it: left in place, a SIGTERM meant to end the host later raised
    :class:`Terminated` wherever the host happened to be (a pytest-xdist worker printed a
    traceback and stayed alive)."""
    hook = sys.unraisablehook
    before = _route()
    try:
        yield
    finally:
        if not OWNED:
            sys.unraisablehook = hook
            for signum, handler in before.items():
                signal.signal(signum, handler if handler is not None else signal.SIG_DFL)


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """Hold SIGINT/SIGTERM back inside the block; one that arrived is raised after it.

    Masked in this thread, and, in the main thread (where Python runs signal handlers),
    only recorded inside the block: a mask is one thread's, and the kernel hands a signal
    to another thread that does not hold it back (a multiresolution setup's background
    thread), after which Python ran the handler in the main thread inside the block all
    the same."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    held: list[int] = []
    before = _hold_handlers(held.append)
    try:
        yield
    finally:
        for signum, handler in before.items():
            signal.signal(signum, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        if held:  # to this thread: it waits while an enclosing block still holds it back
            signal.raise_signal(held[0])


def _hold_handlers(record: Callable[[int], None]) -> dict[int, Any]:
    """In the main thread, replace the Python handlers of SIGINT/SIGTERM with ``record``
    (of the signal number); returns those replaced (none where a handler was not set from
    Python and so cannot be put back)."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    before: dict[int, Any] = {signum: signal.getsignal(signum) for signum in SIGNALS}
    before = {signum: handler for signum, handler in before.items() if handler is not None}
    for signum in before:
        signal.signal(signum, lambda number, _frame: record(number))
    return before


def block() -> None:
    """Hold SIGINT/SIGTERM back from now on (the ``srarap`` process is on its way out; in a
    process that hosts srarap as a library, nothing changes): masked in this thread, and
    only recorded should one still come. A mask is one thread's: a thread still running
    (a stopped process pool's) takes a signal this one holds back, and Python then ran the
    handler here all the same (a stopped batch lost its summary to a second SIGTERM)."""
    if OWNED:
        signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
        _hold_handlers(_record)


def _record(signum):
    global RECEIVED
    RECEIVED = RECEIVED or signum


def pending() -> signal.Signals | int:
    """The signal that arrived or is waiting (held back), or 0."""
    waiting = [s for s in SIGNALS if s in signal.sigpending()]
    return RECEIVED or (waiting[0] if waiting else 0)


def exit_now(code: int, report: Callable[[str], str] | None = None) -> NoReturn:
    """End the process with ``code``: signals blocked, streams flushed, no teardown.

    A signal that arrived (even one swallowed on the way) or waits turns the code into 130 or
    143 unless it is already one of them; ``report(word)`` then gives the line to print, e.g.
    ``"terminated; no output written"``.
    """
    signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    streams.release()
    _flush(sys.stdout)
    _flush(sys.stderr)
    signum = pending()  # the last look: from here to the exit takes microseconds
    if signum and code not in CODES.values():
        code = CODES[signal.Signals(signum)]
        if report is not None:
            _write(sys.stderr, f"srarap: error: {report(WORDS[signal.Signals(signum)])}\n")
            _flush(sys.stderr)
    os._exit(code)


def _write(stream, text):
    try:
        stream.write(text)
    except (OSError, ValueError):  # stderr closed or full: the exit code still tells
        pass


def _flush(stream):
    try:
        stream.flush()
    except (OSError, ValueError):  # a closed pipe: what was not read is nobody's loss
        pass
