"""Refuse work that would not fit in memory, early and with an estimate; recognize running out.

What srarap may plan to use is the least of: ``$SRARAP_MEMORY_LIMIT`` (bytes), the memory the
system has available, what the process's address-space and data limits (``ulimit -v``,
``ulimit -d``) leave beyond what is mapped, and its cgroup's memory limit (a container's).
Each later allocation that fails anyway (numpy, SuperLU, libigl, a worker thread) is reported
as "out of memory" with exit code 4.
"""
import math
import os
import resource
import signal
import threading
import time

from .errors import InputError
from .memory import status_bytes

# Measured on this project's machines (README, "Limits"): an SR solve takes about 4 KB per
# vertex on a long bar, more where the factorizations fill in; this carries a safety margin.
# (What parsing a file takes, per format, is the format table's read_factor: io.mesh.formats.)
SOLVE_BYTES_PER_VERTEX = 8_000
ENV = "SRARAP_MEMORY_LIMIT"
#: coordinates beyond this would overflow when squared (energies, lengths): a typo, not a pose
MAX_COORDINATE = 1e150
# an address space holds the interpreter and its libraries before any data: 205-290 MB of
# mappings (VmSize) once numpy, scipy, libigl, yaml and click are loaded (where the mappings
# cannot be read, this is assumed)
ADDRESS_SPACE_BASE = 300_000_000
# what the address space must keep free beyond the data: OpenBLAS maps its work buffers
# (32 MiB and more) at its first call and, when it cannot, prints "Memory allocation still
# failed after 10 retries, giving up" and ends the process with code 1 (ulimit -v 400000)
BLAS_RESERVE = 128_000_000
# SuperLU and libigl report a failed allocation in their own words
_OOM_WORDS = ("malloc", "out of memory", "not enough memory", "bad_alloc", "cannot allocate",
              "can't start new thread", "failed to map segment")
#: a thread a library could not start (libigl's, under ``ulimit -v``: pthread_create's EAGAIN
#: as a RuntimeError); as an OSError the same words are a busy pipe, not memory
_THREAD_WORDS = ("resource temporarily unavailable",)


def _from_env():
    text = os.environ[ENV].strip()
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value <= 0 or value > 2 ** 62 or len(text) > 19:
        raise InputError(f"{ENV}={os.environ[ENV]!r}: expected a positive number of bytes "
                         "(at most 4.6e18)")
    return int(value)


def _system_available():
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):  # no /proc (not Linux): ask the C library
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


#: the address space srarap needs to load its libraries, start BLAS and run a small job:
#: below about 400 MB (``ulimit -v``) an import failed ("failed to map segment"), ran out of
#: memory, or spun in OpenBLAS's allocation retries with SIGTERM held back (an import's
#: signals wait for its end); a 26-vertex job was refused up to 500 MB (its room less
#: :data:`BLAS_RESERVE`) and ran from 520 MB. Refused below, with this figure in the line, so
#: that every limit from here up runs a small job (tests/test_signals_and_memory.py sweeps)
MIN_START = 560_000_000
#: the same for the data limit (``ulimit -d``: private writable mappings, VmData): at 240-260
#: MB OpenBLAS gave up ("Memory allocation still failed after 10 retries", exit 1), at
#: 280-300 MB it retried for ever with SIGTERM held back, the small job was refused up to
#: 360 MB and ran from 400 MB
MIN_START_DATA = 440_000_000
#: seconds a child is given to start BLAS and a thread under a limit (it takes milliseconds)
PROBE_SECONDS = 10.0


class _Limit:
    def __init__(self, words: str, which: int, field: str, floor: int, base: int):
        self.words, self.which, self.field, self.floor, self.base = \
            words, which, field, floor, base

    def soft(self) -> int | None:
        soft, _ = resource.getrlimit(self.which)
        return None if soft == resource.RLIM_INFINITY else soft

    def left(self) -> int | None:
        """What the limit leaves for data: the limit less what is mapped now (the libraries,
        the data read) and :data:`BLAS_RESERVE`; None without a limit. The reserve stays
        after BLAS has started: OpenBLAS maps a buffer for each thread that calls it, and one
        it cannot map ends the process (a 2.9k-vertex solve at 700 MB, its main thread's
        buffers mapped). (A thread whose stack does not fit is not started: its blocks run
        on the calling thread.)"""
        soft = self.soft()
        if soft is None:
            return None
        mapped = status_bytes(self.field)
        return max(soft - (self.base if mapped is None else mapped) - BLAS_RESERVE, 0)


_LIMITS = (_Limit("ulimit -v", resource.RLIMIT_AS, "VmSize", MIN_START, ADDRESS_SPACE_BASE),
           _Limit("ulimit -d", resource.RLIMIT_DATA, "VmData", MIN_START_DATA,
                  ADDRESS_SPACE_BASE))
_started = threading.Event()


def _address_space():
    """The least that ``ulimit -v`` and ``ulimit -d`` leave (see :class:`_Limit`), or None."""
    known = [left for left in (limit.left() for limit in _LIMITS) if left is not None]
    return min(known) if known else None


def check_start() -> None:
    """Refuse to load the numeric libraries in an address space or data limit too small for
    them (exit 4, one line), before an import can fail or hang there."""
    for limit in _LIMITS:
        soft = limit.soft()
        if soft is not None and soft < limit.floor:
            raise InputError(f"out of memory: {limit.words} allows {_amount(soft)}; srarap "
                             f"needs at least {_amount(limit.floor)} to load numpy, scipy and "
                             f"libigl (raise {limit.words})")


def start_libraries() -> None:
    """Under a memory limit, start BLAS (its work buffers) and a thread in a child process
    first, then here. Where they do not fit, OpenBLAS ends the process ("Memory allocation
    still failed after 10 retries", exit 1) or retries for ever with SIGTERM held back, at
    limits that are not monotonic in size: a child that fails or takes more than
    :data:`PROBE_SECONDS` is refused in one line (exit 4) instead. Without a limit, nothing
    (they start at their first use)."""
    binding = [limit for limit in _LIMITS if limit.soft() is not None]
    if not binding or _started.is_set():
        return
    if not _starts_in_child():
        words = " and ".join(f"{limit.words} allows {_amount(limit.soft() or 0)}"
                             for limit in binding)
        raise InputError(f"out of memory: {words}; numpy's BLAS could not start in it "
                         f"(raise {binding[0].words})")
    _start_here()


def _start_here():
    import numpy as np
    a = np.ones((64, 64))
    a @ a  # OpenBLAS maps its buffers at its first product
    helper = threading.Thread(target=lambda: None)
    helper.start()
    helper.join()
    _started.set()


def _starts_in_child() -> bool:
    pid = os.fork()
    if pid == 0:  # the child: quiet (OpenBLAS's message is the parent's to put in words)
        code = 1
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, 1)
            os.dup2(null, 2)
            _start_here()
            code = 0
        finally:
            os._exit(code)
    deadline = time.monotonic() + PROBE_SECONDS
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status) == 0
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return False
        time.sleep(0.005)


def address_space_left() -> int | None:
    """Bytes the address-space and data limits (``ulimit -v``, ``ulimit -d``) leave beyond
    what is mapped now, the lesser; None without a limit. 0 where the mappings cannot be
    read (not Linux): nothing is known to fit."""
    left = []
    for limit in _LIMITS:
        soft = limit.soft()
        if soft is not None:
            mapped = status_bytes(limit.field)
            left.append(0 if mapped is None else max(soft - mapped, 0))
    return min(left) if left else None


def _cgroup():
    """The cgroup v2 (or v1) memory limit less what the group uses, or None."""
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                          "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            with open(limit) as fh:
                text = fh.read().strip()
            if text == "max" or int(text) >= 2 ** 60:
                return None
            with open(usage) as fh:
                used = int(fh.read().strip())
            return max(int(text) - used, 0)
        except (OSError, ValueError):
            continue
    return None


def available_memory() -> int | None:
    """Bytes srarap may plan to use (see the module's docstring), or None if unknown."""
    if os.environ.get(ENV, "").strip():
        return _from_env()
    known = [v for v in (_system_available(), _address_space(), _cgroup()) if v is not None]
    return min(known) if known else None


def memory_note() -> str:
    """Where the process's memory bound comes from, for messages."""
    if os.environ.get(ENV, "").strip():
        return f"{ENV}={os.environ[ENV].strip()}"
    spaces = [(left, limit.words) for limit in _LIMITS if (left := limit.left()) is not None]
    if spaces:
        return min(spaces)[1]
    if _cgroup() is not None:
        return "the container's memory limit"
    return "the memory available"


def is_out_of_memory(exc: BaseException) -> bool:
    """Whether ``exc`` is a failed allocation reported as something else (SuperLU's malloc
    failures arrive as RuntimeError, C++'s bad_alloc as various types, a thread that could
    not get its stack as RuntimeError, a library that could not be mapped as ImportError)."""
    text = str(exc).lower()
    return isinstance(exc, (RuntimeError, OSError, ValueError, ImportError)) and any(
        word in text for word in _OOM_WORDS) or (isinstance(exc, OSError) and exc.errno == 12) \
        or (type(exc) is RuntimeError and any(word in text for word in _THREAD_WORDS))


def _refuse(what, need, have):
    raise InputError(f"{what} needs about {_amount(need)} of memory, {_amount(have)} "
                     f"available to it ({memory_note()}; set {ENV} to change the assumption)")


def _amount(n):
    """Bytes as a reader wants them: 1.2 GB, 48 MB, 20 kB ("0.0 GB" said nothing)."""
    return (f"{n / 1e9:.1f} GB" if n >= 1e9 else f"{n / 1e6:.0f} MB" if n >= 1e6
            else f"{n / 1e3:.0f} kB")


def check_read(path: str | os.PathLike, factor: float) -> None:
    """Before reading: refuse a mesh file whose parsing would not fit, ``factor`` being the
    bytes of memory parsing holds per byte of the file."""
    have = available_memory()
    if have is None or not os.path.isfile(path):
        return
    check_read_size(path, factor * os.path.getsize(path), have)


def check_read_size(what: str | os.PathLike, need: float, have: int | None) -> None:
    """Refuse reading ``what`` when ``need`` bytes of memory exceed ``have`` (None: unknown)."""
    if have is not None and need > have:
        _refuse(f"{what}: reading it", need, have)


def check_solve(path: str, n_vertices: int) -> None:
    """Before solving: refuse a mesh whose solve would not fit."""
    have = available_memory()
    need = SOLVE_BYTES_PER_VERTEX * n_vertices
    if have is not None and need > have:
        _refuse(f"{path}: deforming its {n_vertices} vertices", need, have)
