"""Run Python source in a fresh interpreter: bytes in on its stdin, bytes out from its stdout.

The multiresolution setup overlaps the simplification (main thread) with the full-resolution
setup (a background thread). METIS's nested dissection, part of the latter, is a C++ call
that keeps the GIL for its whole run (4.2 s at 738k vertices, 7 s at 1.2M), and the
simplification stood still meanwhile: it runs in another process instead.

That process is a fresh interpreter, not a fork of this one: a fork copies a process whose
other threads (this process's simplification, a host's: a test runner's, a notebook's) may
hold locks that the copy then waits on forever, and Python 3.12 deprecates it for that
reason. A fresh interpreter shares nothing; it costs about 0.2 s to start, so small graphs
stay in this process.

Where the child cannot start or fails, :func:`run_fresh` says so and the caller computes the
result itself, so results never depend on this.
"""
import os
import subprocess
import sys

#: what the child runs first: it dies with this process (Linux; the argument is this
#: process's id) and reads its input, so that it never outlives an interrupted run
PRELUDE = """\
import os, sys
try:
    import ctypes
    ctypes.CDLL(None).prctl(1, 9, 0, 0, 0)  # PR_SET_PDEATHSIG, SIGKILL
except Exception:
    pass
if os.getppid() != int(sys.argv[1]):
    sys.exit(1)
payload = sys.stdin.buffer.read()
"""


def run_fresh(source: str, payload: bytes) -> bytes | None:
    """Python ``source`` in a fresh interpreter, with ``payload`` (bytes) in the variable
    ``payload``; what it writes to ``sys.stdout.buffer`` comes back.

    Returns
    -------
    bytes, or None where the interpreter could not start or the code failed (its error
    stays in the child: the caller computes the result itself)

    Examples
    --------
    >>> run_fresh("sys.stdout.buffer.write(payload[::-1])", b"abc") in (b"cba", None)
    True
    """
    try:
        done = subprocess.run([sys.executable, "-c", PRELUDE + source, str(os.getpid())],
                              input=payload, capture_output=True, check=False)
    except (OSError, ValueError, subprocess.SubprocessError):
        return None
    return done.stdout if done.returncode == 0 else None
