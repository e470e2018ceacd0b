"""Run a function that holds the GIL in a forked child, so the process's other thread goes on.

The multiresolution setup overlaps the simplification (main thread) with the full-resolution
setup (a background thread). METIS's nested dissection, part of the latter, is a C++ call
that keeps the GIL for its whole run (4.2 s at 738k vertices, 7 s at 1.2M), and the
simplification stood still meanwhile. In a forked child it holds only the child's GIL; its
result comes back through a pipe.

Where ``os.fork`` is missing (Windows) or the child fails, :func:`run_forked` says so and
the caller computes the result itself, so results never depend on this.
"""
import os
import sys
import warnings
from collections.abc import Callable
from typing import Any

#: macOS lists fork, but forking a process that has loaded system frameworks is unsafe there
_FORK_OK = hasattr(os, "fork") and sys.platform.startswith("linux")


def run_forked(func: Callable, *args: Any) -> bytes | None:
    """``func(*args)``, which returns bytes, computed in a forked child.

    Returns
    -------
    bytes, or None where there is no fork or the child failed (then nothing of ``func`` ran
    in this process: the caller runs it itself)

    Examples
    --------
    >>> out = run_forked(lambda n: bytes(range(n)), 4)
    >>> out in (b"\\x00\\x01\\x02\\x03", None)
    True
    """
    if not _FORK_OK:
        return None
    read_end, write_end = os.pipe()
    try:
        with warnings.catch_warnings():  # Python 3.12+ warns of fork beside other threads:
            # the child only computes, writes and leaves, touching no lock they could hold
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
    except OSError:
        os.close(read_end)
        os.close(write_end)
        return None
    if pid == 0:  # the child: never returns
        _child(write_end, read_end, func, args)
    os.close(write_end)
    with os.fdopen(read_end, "rb") as pipe:
        out = pipe.read()
    _, status = os.waitpid(pid, 0)
    return out if os.waitstatus_to_exitcode(status) == 0 else None


def _child(write_end, read_end, func, args):
    code = 1
    try:
        os.close(read_end)
        data = memoryview(func(*args))
        while data:
            data = data[os.write(write_end, data):]
        code = 0
    finally:  # whatever happened (an exception, an interrupt), the child ends here
        os._exit(code)
