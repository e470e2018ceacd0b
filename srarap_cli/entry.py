"""The console entry point: signal handling first, then the command line, then one way out.

SIGINT and SIGTERM are held back from this module's first line until srarap's handlers are
installed, so that one arriving while Python still loads srarap's modules ends the run with
one line and the documented code (only the interpreter's own start, before this line, is
Python's). The process ends through :func:`srarap_cli.runtime.signals.exit_now`: no
interpreter teardown, so neither a background thread nor a late signal can turn a finished
run into a crash.
"""
import _signal  # the C module: ``signal`` itself takes milliseconds to import (enum)
import sys

# only in the ``srarap`` process itself (console script or ``python -m srarap_cli``): a
# program that imports this module (a test runner collecting it) keeps its signals
_HOLD = {_signal.SIGINT, _signal.SIGTERM} if getattr(sys, "argv", [""])[0].endswith(
    ("srarap", "__main__.py")) else set()
_signal.pthread_sigmask(_signal.SIG_BLOCK, _HOLD)

import signal  # noqa: E402 -- after the signals are held

from .runtime import clock, descriptors, exit_codes, signals  # noqa: E402, F401 -- the clock starts here


def main() -> None:
    descriptors.reopen_closed()
    signals.own()
    code = 1
    try:
        code = _run()
    finally:  # a signal anywhere in the run or its handlers below still ends here
        _leave(code)


def _run() -> int:
    try:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _HOLD)  # one that came is raised here
        from .cli import main as command
        command(prog_name="srarap")
        return 0
    except SystemExit as exc:
        if not isinstance(exc.code, (int, type(None))):
            sys.stderr.write(f"{exc.code}\n")
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except KeyboardInterrupt:
        signals.streams.release()
        sys.stderr.write(f"srarap: error: interrupted; {_written()}\n")
        return exit_codes.INTERRUPTED
    except signals.Terminated:
        signals.streams.release()
        sys.stderr.write(f"srarap: error: terminated; {_written()}\n")
        return exit_codes.TERMINATED
    except Exception as exc:  # noqa: BLE001 -- past every command's own boundary: one line,
        # not the silent exit 1 that leaving without the interpreter's teardown would give
        sys.stderr.write(f"srarap: error: internal error: {type(exc).__name__}: {exc}\n")
        return 1


def _leave(code: int) -> None:
    """The process's one way out. A signal that lands on the way (after the summary line,
    say) is not a crash: it is recorded, and the exit reports it with its code (see
    :func:`srarap_cli.runtime.signals.exit_now`)."""
    for _ in range(3):
        try:
            signals.exit_now(code, lambda word: f"{word}; {_written()}")
        except BaseException:  # the signal that raised is recorded: leave again
            code = 1


def _written():
    """What had been committed (the command line's account of it, when it was loaded)."""
    common = sys.modules.get("srarap_cli.cli.common")
    return common.written() if common is not None else "no output written"
