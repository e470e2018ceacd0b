"""The console entry point: signal handling first, then the command line.

Installed before anything is imported, so that SIGINT or SIGTERM while Python is still
loading modules ends the run with one line and the documented code, not a traceback or a
silent death.
"""
import sys

from .runtime import signals


def main():
    signals.install()
    try:
        from .cli import main as command
    except KeyboardInterrupt:
        sys.stderr.write("srarap: error: interrupted; no output written\n")
        sys.exit(130)
    except signals.Terminated:
        sys.stderr.write("srarap: error: terminated; no output written\n")
        sys.exit(143)
    command(prog_name="srarap")
