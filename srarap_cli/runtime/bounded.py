"""Run code srarap does not own (a third-party file reader) where it cannot take srarap with
it: in a child process with a bound on its time and its memory, which srarap kills when the
bound is passed or when srarap itself is told to stop.

meshio's Tecplot and MDPA readers loop forever on a truncated file, h5py hangs on a damaged
HDF5 file ignoring SIGTERM and SIGINT, and a count a file declares (4,294,967,295 points in a
2 KB VTK file) is allocated before anything checks it. In a child, the loop ends at the time
bound, the hang ends with the child (SIGKILL, which nothing ignores) while srarap exits
130/143 with its one line, and the allocation fails against the child's address-space limit
instead of taking the machine's memory.

The child is forked (the reader's modules are loaded already: no start-up cost) where this
process runs a single thread, else forked by a fresh interpreter kept for it (see
:mod:`.forking`: a fork beside other threads can copy a lock one of them holds; and
:mod:`.child_server`), or, where that server cannot run, it is a fresh interpreter of its
own; it sends its result back pickled through a pipe. Without ``os.fork`` (or with
``SRARAP_BOUNDED=0``) the call runs in this process, unbounded.
"""
import os
import pickle
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

from . import child_server, forking
from .child_call import imported, readable, run_child
from .fresh_process import PRELUDE

#: seconds a bounded call may take at least, and per megabyte of its input on top
#: (``SRARAP_READ_SECONDS`` replaces the first: tests of hostile files use a short one)
BASE_SECONDS, SECONDS_PER_MB = 20.0, 2.0
ENV_SECONDS, ENV_OFF = "SRARAP_READ_SECONDS", forking.ENV_OFF


class OutOfTime(Exception):
    """The call passed its time bound (and its process was killed)."""


class OutOfMemory(Exception):
    """The call needed more memory than its bound (an allocation failed in its process)."""


def time_bound(size_bytes: int) -> float:
    """Seconds a read of ``size_bytes`` may take: the base (``$SRARAP_READ_SECONDS`` where it
    is a positive number) plus :data:`SECONDS_PER_MB` a megabyte."""
    try:
        base = float(os.environ.get(ENV_SECONDS, ""))
    except ValueError:
        base = BASE_SECONDS
    base = base if base > 0 else BASE_SECONDS
    return base + SECONDS_PER_MB * size_bytes / 1e6


def run_bounded(func: Callable[..., Any], *args: Any, seconds: float,
                memory: int | None, preload: Sequence[str] = ()) -> Any:
    """``func(*args)`` in a child process given ``seconds`` and ``memory`` bytes of address
    space beyond what it starts with (None: no memory bound). Returns its result or raises
    its exception (both pickled back); raises :class:`OutOfTime` or :class:`OutOfMemory`
    past a bound. A signal that ends this process kills the child first. ``preload``: the
    modules ``func`` imports, imported once by whatever forks the child (this process or
    the child server) rather than by every child."""
    with start_bounded(func, *args, seconds=seconds, memory=memory,
                       preload=preload) as call:
        return call.result()


def start_bounded(func: Callable[..., Any], *args: Any, seconds: float,
                  memory: int | None, need: str = "bound",
                  preload: Sequence[str] = ()) -> "Pending":
    """:func:`run_bounded` started, not waited for: this process goes on (reads another
    file, say) while the child works; :meth:`Pending.result` waits. Use it in a ``with``
    block: leaving the block without the result (an error, a signal) kills the child.
    ``need`` (:func:`.forking.how`): ``bound`` runs in a child, forked or fresh; ``beside``
    (work apart only to run side by side) in a forked child, or here, at
    :meth:`Pending.result`, unbounded, where this process may not fork. A fresh child
    imports ``func`` by name: a function of a module."""
    way = forking.how(need)
    if way == "here":
        return Pending(lambda: func(*args))
    end = time.monotonic() + seconds
    served = child_server.start(func, args, memory, preload) if way == "fresh" else None
    if served is not None:
        pidfd, read = served
        return Pending(None, (None, read, end, seconds, partial(child_server.reap, pidfd)))
    if way == "fork":
        imported(preload)
    pid, read = (_fork if way == "fork" else _fresh)(func, args, memory)
    return Pending(None, (pid, read, end, seconds, partial(_reap, pid)))


def _fork(func, args, memory):
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        os.close(read)
        run_child(write, func, args, memory)
    os.close(write)
    return pid, read


#: what a fresh child runs after the prelude (it dies with this process, reads the call
#: from its standard input): it answers as a forked child does, on its standard output
_FRESH = PRELUDE + """\
import pickle
from srarap_cli.runtime.child_call import run_child
out = os.dup(1)
os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
run_child(out, *pickle.loads(payload))
"""


def _fresh(func, args, memory):
    payload = pickle.dumps((func, args, memory), protocol=pickle.HIGHEST_PROTOCOL)
    child = subprocess.Popen([sys.executable, "-c", _FRESH, str(os.getpid())],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL)
    assert child.stdin is not None and child.stdout is not None
    read = os.dup(child.stdout.fileno())
    child.stdout.close()
    try:
        child.stdin.write(payload)
        child.stdin.close()
    except OSError:  # it ended before it read: its answer says so (none)
        pass
    return child.pid, read


def map_forked(func: Callable[[Any], Any], items: list, parts: int,
               seconds: float) -> list:
    """``[func(x) for x in items]`` in ``parts`` contiguous runs, each but the last in a
    child process (forked: what this process holds, the children have), the last here; the
    results in order, pickled back. For independent CPU-bound work that holds the GIL (a
    file's parse, a matplotlib figure), where threads would take turns. One part, or a
    process that may not fork now (:func:`.forking.how`: other threads run), runs here.

    Examples
    --------
    >>> map_forked(lambda x: x * x, [1, 2, 3, 4, 5], parts=2, seconds=60)
    [1, 4, 9, 16, 25]
    """
    parts = max(1, min(parts, len(items)))
    cut = [len(items) * k // parts for k in range(parts + 1)]
    runs = [items[cut[k]:cut[k + 1]] for k in range(parts)]

    def run(part):
        return [func(x) for x in part]
    calls = [start_bounded(run, part, seconds=seconds, memory=None, need="beside")
             for part in runs[:-1]]
    try:
        last = run(runs[-1])
        return [x for call in calls for x in call.result()] + last
    finally:
        for call in calls:
            call.__exit__()


class Pending:
    """A call of :func:`start_bounded`: in a child process, or to run here."""

    def __init__(self, here: Callable[[], Any] | None,
                 child: tuple[int | None, int, float, float, Callable[[bool], None]]
                 | None = None) -> None:
        self._here, self._child = here, child
        #: the child's process id, where it is this process's child (None: the call runs
        #: here, or in a child of the :mod:`.child_server`)
        self.pid = None if child is None else child[0]

    def result(self) -> Any:
        """The call's result, or its exception raised here (see :func:`run_bounded`)."""
        if self._child is None:
            return self._here() if self._here is not None else None
        _, read, end, seconds, reap = self._child
        self._child = None
        data = None
        try:
            data = _collect(read, end, seconds)
        finally:
            os.close(read)
            reap(data is None)
        return _decoded(data)

    def __enter__(self) -> "Pending":
        return self

    def __exit__(self, *exc: object) -> None:
        if self._child is not None:  # left without its result: the child goes too
            _, read, _, _, reap = self._child
            self._child = None
            os.close(read)
            reap(True)


def _decoded(data: bytes | None) -> Any:
    kind, value = pickle.loads(data) if data else ("died", None)
    if kind == "ok":
        return value
    if kind == "memory":
        raise OutOfMemory(value)
    if kind == "error" and isinstance(value, BaseException):
        raise value
    raise OutOfMemory("the reading process ended without a result (killed for memory?)")


def _collect(read: int, end: float, seconds: float) -> bytes:
    """Everything the child writes, until it closes the pipe; OutOfTime past ``end`` (the
    monotonic clock's time ``seconds`` after the start)."""
    chunks: list[bytes] = []
    while True:
        left = end - time.monotonic()
        if left <= 0:
            raise OutOfTime(f"not done in {seconds:.0f} s")
        if not readable(read, min(left, 1.0)):
            continue
        chunk = os.read(read, 1 << 20)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _reap(pid: int, kill: bool) -> None:
    """Wait for the child (no zombie left); ``kill`` it first where it did not finish (past
    its bound, or this process was told to stop)."""
    try:
        if kill:
            os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ChildProcessError, ProcessLookupError):
        pass  # already gone and reaped: nothing left to wait for
