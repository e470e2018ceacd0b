"""Threads for one solve: how many, and an ordered map over blocks whose answers do not depend
on that number.

A solve's per-iteration work is split into blocks that the caller cuts from the mesh (vertex
ranges of fixed size), never from the thread count, and each block's result is returned in
block order, so that the caller combines them in one fixed order: 1, 2 or 16 threads compute
the same floating-point operations in the same order and write the same bytes. numpy's large
operations, scipy's sparse products and rslab's solves release the GIL, so Python threads run
them side by side; BLAS itself stays at one thread (:mod:`.threads`).

How many: :func:`using_threads` sets the count for the code inside it (a command's
``--threads``, a manifest's ``threads``, the API's ``threads=``); where nobody set one, the
environment's ``SRARAP_THREADS``, else the CPUs this process may use (:func:`available_cpus`:
its CPU affinity and its cgroup's CPU quota, so that a container given 2 CPUs on a 64-core
host runs 2 threads, not 64).
"""
import contextlib
import contextvars
import dataclasses
import functools
import math
import os
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, TypeVar

from .errors import InputError
from .numbers import digits_value
from .threads import one_blas_thread

if TYPE_CHECKING:
    import numpy as np

T = TypeVar("T")
R = TypeVar("R")

ENV = "SRARAP_THREADS"
_CGROUP = "/sys/fs/cgroup"

@dataclasses.dataclass(frozen=True)
class Plan:
    """How one kind of work is cut into blocks: at most ``size`` rows a block, of even sizes
    (``even``) or in runs of ``size`` from the start; and below ``alone_below`` rows in all,
    the blocks run in turn on the calling thread (hand-offs cost more than they share)."""

    size: int
    even: bool = True
    alone_below: int = 0


#: The one table of block plans. Blocks are cut from the mesh, never from the thread count,
#: so every thread count computes the same sums in the same order.
#: ``vertices``: per-vertex work (rotors, cells, positions); 16k rows: a block's numpy calls
#: take a millisecond or more against tens of microseconds to hand one to a thread.
#: ``values``: flat vectors, 4 values a vertex (conjugate gradients, Anderson's history).
#: ``edges``: per-edge work summed into cells, runs of 2^18 (a cell's sum is split where a
#: run ends, in the same place at any count).
#: ``collapses``: candidate edge collapses, each a test of two rings (costlier a row).
#: ``alone_below``: a coarse step of the 19.2k-vertex cylinder took 41.8 ms on one thread and
#: 48.1 on two, the 76.8k one 166 and 172 ms, the 307k one 862 and 859 ms
#: (``benchmarks/coarse_step.py``, 2 cores): below 64k vertices a map runs on the calling
#: thread.
PLANS: dict[str, Plan] = {
    "vertices": Plan(1 << 14, alone_below=1 << 16),
    "values": Plan(1 << 16, alone_below=4 << 16),
    "edges": Plan(1 << 18, even=False, alone_below=6 << 16),
    "collapses": Plan(1 << 12),
}


class Blocks(list):
    """Blocks of a :class:`Plan` (or items that stand for them, :meth:`carrying`), and
    whether they run on the calling thread alone (:attr:`alone`)."""

    alone: bool = False

    def carrying(self, items: Iterable[Any]) -> "Blocks":
        """``items`` (one a block, in order) with these blocks' :attr:`alone`."""
        out = Blocks(items)
        out.alone = self.alone
        return out


_count: contextvars.ContextVar[int | None] = contextvars.ContextVar("srarap_threads",
                                                                   default=None)
_ceiling: contextvars.ContextVar[int | None] = contextvars.ContextVar("srarap_thread_ceiling",
                                                                     default=None)
_pools: dict[int, ThreadPoolExecutor] = {}
_pools_lock = threading.Lock()
_inside = threading.local()


@functools.lru_cache(maxsize=8)
def available_cpus(cgroup_root: str = _CGROUP, proc_cgroup: str = "/proc/self/cgroup") -> int:
    """The CPUs this process may use: its affinity mask, capped by its cgroup's CPU quota
    (rounded up: a quota of 1.5 CPUs runs 2 threads), at least 1. Read once per process
    (a solve asks at every block map).

    Examples
    --------
    >>> available_cpus() >= 1
    True
    """
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        cpus = os.cpu_count() or 1
    quota = cgroup_quota(cgroup_root, proc_cgroup)
    if quota is not None:
        cpus = min(cpus, max(1, math.ceil(quota - 1e-9)))
    return max(1, cpus)


def cgroup_quota(root: str = _CGROUP, proc_cgroup: str = "/proc/self/cgroup") -> float | None:
    """CPUs' worth of time the cgroups above this process allow (the smallest along its
    path), or None where nothing caps it. cgroup v2 (``cpu.max``) and v1
    (``cpu.cfs_quota_us`` over ``cpu.cfs_period_us``)."""
    quotas = []
    for path in _cgroup_dirs(root, proc_cgroup):
        quotas.append(_v2_quota(path))
        quotas.append(_v1_quota(path))
    found = [q for q in quotas if q is not None]
    return min(found) if found else None


def _cgroup_dirs(root, proc_cgroup):
    """The cgroup folders of this process and of its parents, for v2 and v1 layouts."""
    try:
        with open(proc_cgroup) as fh:
            lines = fh.read().splitlines()
    except OSError:
        lines = []
    relative = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        controllers, path = parts[1], parts[2]
        if controllers == "":
            relative.append((root, path))
        elif "cpu" in controllers.split(","):
            relative.append((os.path.join(root, "cpu"), path))
            relative.append((os.path.join(root, controllers), path))
    dirs = [root, os.path.join(root, "cpu")]
    for base, path in relative:
        parts = [p for p in path.split("/") if p and p != ".."]
        dirs += [os.path.join(base, *parts[:k]) for k in range(len(parts) + 1)]
    return list(dict.fromkeys(dirs))


def _v2_quota(folder):
    text = _read(os.path.join(folder, "cpu.max"))
    if text is None:
        return None
    fields = text.split()
    if len(fields) != 2 or fields[0] == "max":
        return None
    return _ratio(fields[0], fields[1])


def _v1_quota(folder):
    quota = _read(os.path.join(folder, "cpu.cfs_quota_us"))
    period = _read(os.path.join(folder, "cpu.cfs_period_us"))
    if quota is None or period is None:
        return None
    return _ratio(quota, period)


def _ratio(quota, period):
    try:
        q, p = int(quota), int(period)
    except ValueError:
        return None
    return q / p if q > 0 and p > 0 else None


def _read(path):
    try:
        with open(path) as fh:
            return fh.read().strip()
    except OSError:
        return None


def default_threads() -> int:
    """``$SRARAP_THREADS`` (a positive integer) where set, else :func:`available_cpus`.

    Raises InputError (exit 4) naming the variable for any other value."""
    text = os.environ.get(ENV, "").strip()
    if not text:
        return available_cpus()
    value = thread_count(text)
    if value is None:
        raise InputError(f"{ENV}={os.environ[ENV]!r}: expected a positive whole number of "
                         "threads")
    return value


def thread_count(value: object) -> int | None:
    """A thread count as every place that takes one reads it (``--threads``,
    ``$SRARAP_THREADS``, the ``threads`` setting): a positive integer, or its ASCII digits
    as text; None for anything else (``1_0``, ``٢``, ``1.5``, ``true``).

    Examples
    --------
    >>> thread_count("12"), thread_count(3), thread_count("1_0"), thread_count("\u0662")
    (12, 3, None, None)
    """
    if isinstance(value, str):
        text = value.strip()
        if not (text.isascii() and text.isdigit()):
            return None
        value = digits_value(text)  # 5000 digits: a count as large as any, capped alike
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        return None
    return value


def worker_share(workers: int, asked: int | None = None) -> int:
    """Threads for each of ``workers`` side by side (a batch's worker processes): its share
    of the CPUs this process may use (at least 1), or less where ``asked`` (``--threads``)
    or ``$SRARAP_THREADS`` says so.

    Examples
    --------
    >>> worker_share(10 ** 6)
    1
    """
    share = max(1, available_cpus() // max(1, workers))
    if asked is None and os.environ.get(ENV, "").strip():
        asked = default_threads()
    return share if asked is None else max(1, min(asked, share))


def cap_note(asked: int | None) -> list[str]:
    """The ``-v`` line that says a thread count (``asked``: ``--threads`` or the setting;
    None: ``$SRARAP_THREADS`` or the CPUs) was capped at the CPUs this process may use, or
    nothing where it was not.

    Examples
    --------
    >>> cap_note(1)
    []
    """
    count = default_threads() if asked is None else asked
    cpus = available_cpus()
    if count <= cpus:
        return []
    return [f"srarap: threads: {count} asked, {cpus} used (the CPUs this process may use: "
            "a count is capped there, and the results do not depend on it)"]


def current_threads() -> int:
    """The thread count of the code running now (see the module's docstring), within any
    :func:`at_most` around it, and never more than the CPUs this process may use
    (:func:`available_cpus`): a larger request (``--threads 100000``) is capped here, where
    every solve, factorization and pool asks, and since the results do not depend on the
    count, the bytes do not either."""
    count = _count.get()
    count = default_threads() if count is None else count
    ceiling = _ceiling.get()
    count = count if ceiling is None else min(count, ceiling)
    return min(count, available_cpus())


@contextlib.contextmanager
def at_most(ceiling: int) -> Iterator[None]:
    """Inside the block, no solve runs more than ``ceiling`` threads, whatever it asks for
    (a batch's share of the CPUs per worker).

    Examples
    --------
    >>> with at_most(1), using_threads(8):
    ...     current_threads()
    1
    """
    token = _ceiling.set(max(1, ceiling))
    try:
        yield
    finally:
        _ceiling.reset(token)


@contextlib.contextmanager
def using_threads(count: int | None) -> Iterator[int]:
    """Inside the block, solves run ``count`` threads (None: the default); yields the count.

    Examples
    --------
    >>> with using_threads(1) as n:
    ...     n, current_threads()
    (1, 1)
    """
    if count is not None and (isinstance(count, bool) or not isinstance(count, int)
                              or count < 1):
        raise ValueError(f"threads must be a positive integer, not {count!r}")
    # resolved once here: the default reads the environment and the cgroup's files
    token = _count.set(count if count is not None else _count.get() or default_threads())
    resolved = current_threads()
    try:
        yield resolved
    finally:
        _count.reset(token)


def numerics(func: Callable[..., R]) -> Callable[..., R]:
    """The one wrapper of a solver's front door (a deformer's setup, its solve): the
    wrapped call takes a keyword ``threads`` (None: the default, see :func:`using_threads`)
    and runs on that many threads of ours, with one BLAS thread (see
    :func:`.threads.one_blas_thread`).

    Examples
    --------
    >>> @numerics
    ... def count():
    ...     return current_threads()
    >>> count(threads=1)
    1
    """
    @functools.wraps(func)
    def wrapper(*args: Any, threads: int | None = None, **kwargs: Any) -> R:
        with one_blas_thread(), using_threads(threads):
            return func(*args, **kwargs)

    return wrapper


def blocks(n: int, kind: str = "vertices") -> Blocks:
    """Consecutive ranges covering ``range(n)`` (none for 0) by the plan of ``kind`` (see
    :data:`PLANS`): as many as blocks of at most its size need, of even sizes (19,200 rows
    make two blocks of 9,600, not 16,384 and 2,816: neither thread waits long for the
    other), or runs of its size from the start. A function of ``n`` and the plan alone.

    Examples
    --------
    >>> [b.stop - b.start for b in blocks(40_000)]
    [13333, 13333, 13334]
    >>> blocks(40_000).alone, blocks(10 ** 6).alone
    (True, False)
    """
    plan = PLANS[kind]
    out = Blocks(cut(n, plan.size) if plan.even else
                 [slice(a, min(a + plan.size, n)) for a in range(0, n, plan.size)])
    out.alone = n < plan.alone_below
    return out


def cut(n: int, size: int) -> list[slice]:
    """``range(n)`` in the fewest consecutive ranges of at most ``size``, of even sizes.

    Examples
    --------
    >>> cut(5, 2)
    [slice(0, 1, None), slice(1, 3, None), slice(3, 5, None)]
    >>> [b.stop - b.start for b in cut(10, 4)]
    [3, 3, 4]
    """
    count = -(-n // size)
    bounds = [k * n // count for k in range(count + 1)] if count else []
    return [slice(a, b) for a, b in zip(bounds, bounds[1:])]


def splits(n: int, kind: str = "vertices") -> bool:
    """Whether ``n`` rows make more than one block of ``kind`` (else the caller's plain code
    runs: the same arithmetic, without the blocks' calls)."""
    return n > PLANS[kind].size


def ordered_sum(func: Callable[[T], Any], items: Iterable[T], start: Any = 0.0) -> Any:
    """``start + func(b0) + func(b1) + ...``, the blocks mapped side by side
    (:func:`map_blocks`) and their parts added in block order: the same sum at every thread
    count. Parts may be floats or arrays (``start`` then an array of their shape, added to
    in place).

    Examples
    --------
    >>> ordered_sum(lambda s: float(sum(range(s.start, s.stop))), cut(10, 4))
    45.0
    """
    total = start
    for part in map_blocks(func, items):
        total += part
    return total


def map_blocks(func: Callable[[T], R], items: Iterable[T]) -> list[R]:
    """``[func(b) for b in items]`` (blocks, or what stands for them), run on the current
    thread count; the results in block order, whatever order the blocks finished in. The
    calling thread takes blocks too (a hand-off to another thread costs tens of
    microseconds, a block a millisecond). One thread, one block, blocks too small to share
    (:attr:`Blocks.alone`) or a call from inside a block (no nested pools: they could wait
    on each other) runs them in turn here. A block that raises: the first such error in
    block order is raised, once every block has ended.

    Examples
    --------
    >>> with using_threads(2):
    ...     map_blocks(lambda k: k * k, range(5))
    [0, 1, 4, 9, 16]
    """
    alone = getattr(items, "alone", False)
    items = list(items)
    count = min(current_threads(), len(items))
    if count <= 1 or alone or getattr(_inside, "busy", False):
        return [func(item) for item in items]
    results: list = [None] * len(items)
    errors: dict[int, BaseException] = {}
    order = iter(range(len(items)))
    lock = threading.Lock()

    def take_blocks():
        busy, _inside.busy = getattr(_inside, "busy", False), True
        try:
            while True:
                with lock:
                    k = next(order, None)
                if k is None:
                    return
                try:
                    results[k] = func(items[k])
                except BaseException as exc:  # handed to the caller, in block order
                    errors[k] = exc
        finally:
            _inside.busy = busy

    context = contextvars.copy_context()
    helpers = []
    try:
        pool = _pool(count - 1)
        for _ in range(count - 1):
            helpers.append(pool.submit(context.copy().run, take_blocks))
    except RuntimeError:  # a thread that cannot start (no room for its stack): this thread
        pass              # takes the blocks instead, and the answer is the same
    take_blocks()
    for helper in helpers:
        helper.result()
    if errors:
        raise errors[min(errors)]
    return results


def fill(func: Callable[..., object], out: "np.ndarray", *arrays: "np.ndarray",
         kind: str = "vertices") -> "np.ndarray":
    """``out[r] = func(*(a[r] for a in arrays))`` for each block ``r`` of :func:`blocks` of
    ``len(out)`` rows of ``kind``, blocks side by side; returns ``out``. For row-wise work,
    whose rows come out the same however they are cut.

    Examples
    --------
    >>> import numpy as np
    >>> fill(lambda a: 2 * a, np.empty(3), np.arange(3.0))
    array([0., 2., 4.])
    """
    def block(rows):
        out[rows] = func(*(a[rows] for a in arrays))

    map_blocks(block, blocks(len(out), kind))
    return out


def _pool(count):
    with _pools_lock:
        pool = _pools.get(count)
        if pool is None:
            pool = _pools[count] = ThreadPoolExecutor(count, thread_name_prefix="srarap")
        return pool


def _forget_pools():
    """A forked child has none of its parent's threads: its pools start anew (and it may
    run under other CPU limits)."""
    global _pools_lock
    _pools.clear()
    _pools_lock = threading.Lock()
    available_cpus.cache_clear()


os.register_at_fork(after_in_child=_forget_pools)
