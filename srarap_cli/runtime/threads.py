"""One BLAS thread for srarap's numerical work.

The results must not depend on the machine's thread settings: OpenBLAS splits dot products
and matrix products by thread count, which changed the last digits of a solve (4,125 of
4,802 lines of a cylinder's output differed between 1 and 2 threads). The threads bought
nothing either: the work here is sparse (SuperLU, Eigen, scipy's sparse products are single
threaded) and the dense BLAS calls are small, so a second thread only added CPU time, and
under load (``batch --workers 2`` on 2 cores) it slowed everything down. Parallelism comes from
running jobs side by side (``batch --workers``), and from one overlap of independent stages
(:func:`background`: a multiresolution solve's full-resolution setup beside its simplification,
which do not share data, so the results stay the same bit for bit).
"""
import functools
import os
import threading
from collections.abc import Callable
from typing import Any, TypeVar, cast

T = TypeVar("T")
F = TypeVar("F", bound=Callable[..., Any])

_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded(func: F) -> F:
    """Run ``func`` with every BLAS library limited to one thread (threadpoolctl)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return func(*args, **kwargs)

    return cast(F, wrapper)


def pin_process() -> None:
    """Ask the BLAS libraries for one thread before they load (the command line calls this
    first; libraries already loaded keep their pools, which :func:`single_threaded` limits),
    and keep threads in the main malloc arena under an address-space limit."""
    for name in _VARIABLES:
        os.environ[name] = "1"
    _one_arena_under_address_limit()


# glibc's mallopt parameter M_ARENA_MAX
_M_ARENA_MAX = -8


def _one_arena_under_address_limit():
    """Under ``ulimit -v``, each new thread's malloc arena reserves 64-128 MB of address space;
    when that fails glibc retries on every allocation (seen: libigl's worker threads spinning
    in system time for minutes, then "cannot allocate memory for thread-local data: ABORT").
    With a single arena the threads share the main one and a real shortage is a MemoryError."""
    import resource

    if resource.getrlimit(resource.RLIMIT_AS)[0] == resource.RLIM_INFINITY:
        return
    try:
        import ctypes

        ctypes.CDLL(None).mallopt(_M_ARENA_MAX, 1)
    except (OSError, AttributeError):  # not glibc: no per-thread arenas to bound
        pass


def background(func: Callable[[], T]) -> Callable[[], T]:
    """Start ``func()`` in a daemon thread; returns ``wait()``, which gives its result or
    raises its exception.

    For a setup stage that overlaps another one: SuperLU's factorizations and most large
    numpy operations release the GIL. A daemon thread, so that a signal in the main thread
    ends the run at once instead of after the background work.

    Examples
    --------
    >>> wait = background(lambda: 6 * 7)
    >>> wait()
    42
    """
    out = {}

    def run():
        try:
            out["value"] = func()
        except BaseException as exc:  # handed to the waiting thread
            out["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()

    def wait():
        thread.join()
        if "error" in out:
            raise out["error"]
        return out["value"]

    return wait
