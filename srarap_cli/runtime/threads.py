"""One BLAS thread for srarap's numerical work, and the worker processes of a batch.

The results must not depend on the machine's thread settings: OpenBLAS splits dot products
and matrix products by thread count, which changed the last digits of a solve (4,125 of
4,802 lines of a cylinder's output differed between 1 and 2 threads). BLAS threads would buy
little either: the dense BLAS calls are small. A solve's own threads (:mod:`.parallel`) split
its work into blocks cut from the mesh, never from the thread count, so any count gives the
same bytes; jobs run side by side in processes (``batch --workers``), each with its share of
the CPUs; and one overlap of independent stages (:func:`background`: a multiresolution
solve's full-resolution setup beside its simplification and its coarse level's setup and
solve, which do not share data) keeps the results the same bit for bit.
"""
import contextlib
import contextvars
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

from .allocator import own_process
from .environment import environ_changed
from .forking import how
from .signals import deferred

T = TypeVar("T")

_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


_limit_lock = threading.Lock()
_limit: dict[str, Any] = {"holders": 0, "limiter": None}


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Inside the block, every BLAS library runs one thread (threadpoolctl), whichever thread
    entered it and whatever other threads do meanwhile.

    BLAS thread counts are global to the process, and threadpoolctl's own context restores
    the counts it found when it ends: a background stage that outlives the call that
    started it (a full-resolution factorization still running when the coarse solve
    begins) would then run with the host's threads. Here the limit holds from the first
    entry to the last exit, across threads. threadpoolctl lets only one thread at a time
    set OpenBLAS's shared pool (the others are ignored silently), so the thread that sets
    or restores the limit takes that role first and gives it up after.
    """
    with _limit_lock:
        if _limit["holders"] == 0:
            from threadpoolctl import threadpool_limits

            _release_blas_control()
            _limit["limiter"] = threadpool_limits(limits=1, user_api="blas")
            _release_blas_control()
        _limit["holders"] += 1
    try:
        yield
    finally:
        with _limit_lock:
            _limit["holders"] -= 1
            if _limit["holders"] == 0:
                _release_blas_control()
                _limit["limiter"].restore_original_limits()
                _release_blas_control()
                _limit["limiter"] = None


def _release_blas_control():
    """Let any thread set OpenBLAS's thread count next."""
    from threadpoolctl import OpenBLASController

    OpenBLASController.clear_controlling_thread(force=True)


def pin_process() -> None:
    """Ask the BLAS libraries for one thread before they load (the command line calls this
    first; libraries already loaded keep their pools, which :func:`one_blas_thread` limits),
    and take the process's allocator policy (:func:`..allocator.own_process`: the command
    owns its process)."""
    for name in _VARIABLES:
        os.environ[name] = "1"
    own_process()


def background(func: Callable[[], T]) -> Callable[[], T]:
    """Start ``func()`` in a daemon thread; returns ``wait()``, which gives its result or
    raises its exception.

    For a setup stage that overlaps another one: SuperLU's factorizations and most large
    numpy operations release the GIL. A daemon thread, so that a signal in the main thread
    ends the run at once instead of after the background work. ``func`` runs with one BLAS
    thread (:func:`one_blas_thread`), also after the call that started it returned.

    Examples
    --------
    >>> wait = background(lambda: 6 * 7)
    >>> wait()
    42
    """
    out: dict[str, Any] = {}
    context = contextvars.copy_context()  # the caller's thread count (runtime.parallel)

    def run():
        try:
            with one_blas_thread():
                out["value"] = context.run(func)
        except BaseException as exc:  # handed to the waiting thread
            out["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    try:
        thread.start()
    except RuntimeError:  # no room for a thread's stack: the work runs here, in turn
        run()

    def wait():
        if thread.ident is not None:
            thread.join()
        if "error" in out:
            raise out["error"]
        return out["value"]

    return wait


@contextlib.contextmanager
def worker_processes(preload: Sequence[str] = (), threads_ahead: bool = False) -> Iterator[Any]:
    """The multiprocessing context for srarap's worker processes, inside the block.

    ``fork`` (a worker starts with everything imported) where this process may fork
    (:func:`.forking.how`: it runs a single thread) and will while it starts them (not
    ``threads_ahead``: a Dask cluster's own threads start first); else ``forkserver``: a
    fresh, single-threaded server started here, which imports the modules ``preload`` names
    once, so that each worker forked from it starts with them, and which ends with the block
    (a server left from an earlier block, with another environment, is not reused); the
    platform's default where there is no fork server (Windows).

    Examples
    --------
    >>> with worker_processes() as context:
    ...     context.get_start_method() in ("fork", "forkserver", "spawn")
    True
    """
    import multiprocessing

    if sys.platform.startswith("linux") and not threads_ahead and how("workers") == "fork":
        yield multiprocessing.get_context("fork")
    elif "forkserver" not in multiprocessing.get_all_start_methods():
        yield multiprocessing.get_context()
    else:
        _stop_fork_server()
        try:
            yield _start_fork_server(preload)
        finally:
            _stop_fork_server()


def _start_fork_server(preload):
    """Start the server with this ``preload`` and one BLAS thread, which every process it
    forks keeps (started now: a library that sets its own preload later, as Dask does,
    would otherwise replace it)."""
    import multiprocessing
    from multiprocessing import forkserver, resource_tracker

    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(list(preload))
    # the resource tracker's note on semaphores of workers a signal killed is not the
    # user's concern: it cleans them up
    quiet = {"PYTHONWARNINGS": ",".join(filter(None, [
        os.environ.get("PYTHONWARNINGS"), "ignore::UserWarning:multiprocessing.resource_tracker"]))}
    with environ_changed({**dict.fromkeys(_VARIABLES, "1"), **quiet}):
        # the server starts with SIGINT/SIGTERM held back (the mask outlives exec) until
        # its preload has set them: a Ctrl-C during its imports printed their traceback.
        # Python's resource tracker first: starting it unblocks both, whatever the mask was
        resource_tracker.ensure_running()
        with deferred():
            forkserver.ensure_running()
    return context


def _stop_fork_server():
    """Stop the fork server, and first whatever it forked that still runs: the server ends
    only when every process it forked has (they hold its liveness pipe), and a signal that
    stopped the block while a Dask cluster started left workers no one would close."""
    from multiprocessing import forkserver

    server = getattr(forkserver, "_forkserver", None)
    stop = getattr(server, "_stop", None)
    if stop is None:  # CPython's; elsewhere a server ends with this process
        return
    pid = getattr(server, "_forkserver_pid", None)
    if pid is None:
        return stop()
    stopped = threading.Event()

    def end_late_ones():  # a cluster's thread may still ask the server for workers
        while not stopped.wait(0.1):
            end_children(pid)

    end_children(pid)
    watcher = threading.Thread(target=end_late_ones, daemon=True)
    watcher.start()
    try:
        stop()
    finally:
        stopped.set()


#: seconds the processes a fork server left get after SIGTERM before SIGKILL
CHILD_GRACE = 2.0


def end_children(pid: int, grace: float = CHILD_GRACE) -> None:
    """SIGTERM to each process whose parent is ``pid``, SIGKILL to those still there after
    ``grace`` seconds."""
    children = _children(pid)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for child in children:
            try:
                os.kill(child, sig)
            except OSError:  # it ended by itself meanwhile
                pass
        deadline = time.monotonic() + grace
        while children and time.monotonic() < deadline:
            time.sleep(0.02)
            children = [c for c in children if c in _children(pid)]
        if not children:
            return


def _children(pid: int) -> list[int]:
    """The running processes whose parent is ``pid`` (from /proc; none where it is absent)."""
    found: list[int] = []
    try:
        entries = os.listdir("/proc")
    except OSError:
        return found
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as fh:
                fields = fh.read().rsplit(b")", 1)[1].split()
        except OSError:  # the process ended while the list was read
            continue
        if int(fields[1]) == pid and fields[0] != b"Z":
            found.append(int(entry))
    return found
