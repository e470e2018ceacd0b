"""The console entry point: signal handling first, then the command line, then one way out.

Handlers are installed before anything else is imported, so that SIGINT or SIGTERM while
Python is still loading modules ends the run with one line and the documented code. The
process ends through :func:`srarap_cli.runtime.signals.exit_now`: no interpreter teardown, so
neither a background thread nor a late signal can turn a finished run into a crash.
"""
import sys

from .runtime import clock, descriptors, signals  # noqa: F401 -- the clock starts with the process


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
        return 130
    except signals.Terminated:
        signals.streams.release()
        sys.stderr.write(f"srarap: error: terminated; {_written()}\n")
        return 143


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
