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
        from .cli import main as command
        command(prog_name="srarap")
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if not isinstance(exc.code, (int, type(None))):
            sys.stderr.write(f"{exc.code}\n")
    except KeyboardInterrupt:
        signals.streams.release()
        sys.stderr.write(f"srarap: error: interrupted; {_written()}\n")
        code = 130
    except signals.Terminated:
        signals.streams.release()
        sys.stderr.write(f"srarap: error: terminated; {_written()}\n")
        code = 143
    signals.exit_now(code, lambda word: f"{word}; {_written()}")


def _written():
    """What had been committed (the command line's account of it, when it was loaded)."""
    common = sys.modules.get("srarap_cli.cli.common")
    return common.written() if common is not None else "no output written"
