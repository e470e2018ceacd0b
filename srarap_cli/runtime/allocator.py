"""Keep freed memory in the process while it solves (glibc's malloc).

glibc serves every allocation above its mmap threshold (32 MB at most) with a fresh mapping
and unmaps it on free, so each large temporary of an iteration (a 738k-vertex mesh's 4x4
rotor blocks are 94 MB) costs page faults and zeroing again, every time: at 738k vertices
9.4 s of system time in 30 s (setup and 6 iterations), 4.7 s with the memory kept for reuse,
wall time 14% lower, peak resident memory 6% higher. Small meshes allocate below the
threshold and are unaffected. Elsewhere than glibc this does nothing.

Each thread that allocates also gets its own arena by default, and what it frees stays in
that arena for its own reuse: with memory kept, the solve's block threads each held their own
free memory beside the main heap's. One arena shared by all threads lets any thread reuse
what another freed: 1.2M-vertex cylinder, two runs each with one arena (``MALLOC_ARENA_MAX=1``)
and without, peak resident memory 0.14 GB (2.7%) lower, free memory left in the arenas at the
peak 0.87-0.88 GB -> 0.18-0.72 GB; the same seconds and output bytes. (And the 500k-vertex
bar's multiresolution setup, whose factorizations run in threads: peak 2,646 -> 2,539 MiB,
the same wall time. Under ``ulimit -v`` each arena also reserves 64-128 MB, and when that
failed glibc retried on every allocation: libigl's threads spun for minutes, then "cannot
allocate memory for thread-local data: ABORT"; with one arena a shortage is a MemoryError.)

This is process policy: a ``srarap`` command owns its process (:func:`own_process`, at its
start, and in a batch's worker processes), and only then do :func:`one_arena` and
:func:`keep_freed_memory` act. Called through the Python API (``deform``, ``deform_mesh``,
``Deformer``), where the process is its caller's, they do nothing.
"""
import ctypes

# mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD = -1
_M_TOP_PAD = -2
_M_MMAP_MAX = -4
_M_ARENA_MAX = -8
_TOP_PAD = 64 << 20  # heap growth per brk: fewer, larger extensions


def _mallopt():
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return None
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return mallopt


_owned = False


def own_process() -> bool:
    """This process is a command's (``srarap``'s, or a batch worker's): the allocator policy
    applies from now on, one arena at once. Returns whether glibc took it."""
    global _owned
    _owned = True
    return one_arena()


def one_arena() -> bool:
    """Have every thread allocate from the main arena (arenas made before stay in use): in a
    command's process (:func:`own_process`), before its setup starts threads; nothing
    otherwise. Returns whether glibc took the setting."""
    mallopt = _mallopt() if _owned else None
    return mallopt is not None and mallopt(_M_ARENA_MAX, 1) == 1


def keep_freed_memory() -> bool:
    """Serve large allocations from the heap and keep what is freed for reuse (no mmap per
    allocation, no trimming). Process-wide, so called by the commands' tasks once their
    setup is done (deform, animate, and each batch job, also in a Dask worker), never by the
    Python API, which leaves its caller's process alone (nothing unless :func:`own_process`
    was called). Returns whether glibc took the settings."""
    mallopt = _mallopt() if _owned else None
    if mallopt is None:
        return False
    settings = ((_M_MMAP_MAX, 0), (_M_TRIM_THRESHOLD, 2**31 - 1), (_M_TOP_PAD, _TOP_PAD))
    return all(mallopt(param, value) == 1 for param, value in settings)
