"""Standard descriptors that a cron job, a daemon or a CI step closed before starting srarap.

A closed descriptor 0, 1 or 2 is not an error of the run. Left closed, the first file srarap
opens would take its number: a C library's message for descriptor 2 would then land inside an
output mesh. :func:`reopen_closed` points each closed one at the null device before anything
else opens a file, and remembers which were closed: what would go to a closed stream is
dropped, and reading ``-`` or writing ``-o -`` there is refused by name.
"""
import os
import sys

#: descriptors (0, 1, 2) that were closed when the process started
CLOSED: set[int] = set()
_STREAMS = ((0, "stdin", os.O_RDONLY, "r"), (1, "stdout", os.O_WRONLY, "w"),
            (2, "stderr", os.O_WRONLY, "w"))


def reopen_closed() -> None:
    """Point every closed standard descriptor at the null device, and give Python a stream
    for each one it found closed (``sys.stdout`` is None then)."""
    for fd, name, flags, mode in _STREAMS:
        try:
            os.fstat(fd)
        except OSError:
            CLOSED.add(fd)
            null = os.open(os.devnull, flags)  # the lowest free number: ``fd`` itself
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
        if getattr(sys, name) is None:
            setattr(sys, name, open(fd, mode, encoding="utf-8", errors="backslashreplace",
                                    closefd=False))


def closed(fd: int) -> bool:
    """Whether standard descriptor ``fd`` was closed when the process started."""
    return fd in CLOSED


def quiet_stdout() -> None:
    """Point stdout at the null device once its reader went away: flushing what the closed
    pipe did not take would fail again at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
