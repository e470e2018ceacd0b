"""Symmetric positive definite factorizations by rslab: one stored triangle, ``L D Lᵀ``.

rslab (MIT, pure Rust) stores one triangle of the factor where SuperLU stores two, in about
half the memory, and orders and factors faster (1.2M-vertex cylinder Laplacian, one core:
7.7 s and 0.41 s a 4-column solve against SuperLU's 21 s and 0.64 s; peak 2.3 against
2.7 GB). :func:`rslab_factor` answers None wherever it cannot be relied on, and the caller
(:func:`..linalg.factor`) then uses SuperLU:

- rslab is not installed, or ``$SRARAP_FACTOR=superlu`` asks for SuperLU (``rslab`` asks
  for rslab at every size; unset, :func:`..linalg.factor` uses it from
  :data:`..linalg.ONE_TRIANGLE_FROM` rows);
- the matrix is not positive definite (a singular or indefinite matrix factors in ``L D
  Lᵀ`` all the same; SuperLU then reports it as before);
- rslab refused it or could not start its threads (under ``ulimit -v`` they may not get
  their stacks: it raises a Rust panic, whose text is held back);
- this process was forked from one that had used rslab: its thread pool does not survive a
  fork, and a factorization in the child waited forever (seen with one thread too);
- the process runs under an address-space or data limit (``ulimit -v``, ``ulimit -d``):
  rslab's allocator (mimalloc) reserves address space in segments it sizes by what it can
  get, so whether a solve fits was not monotonic in the limit (a 2.9k-vertex solve ran at
  600 and 750 MB and failed at 700: refused, or OpenBLAS ended the process when no room
  was left for a thread's buffer). SuperLU allocates what it uses and reports a failure.

Its plan of the memory a factorization needs is checked against what the process may use
first: a Rust allocation that fails ends the process (SIGABRT), where a plan that does not
fit is SuperLU's, which reports a failed allocation as "out of memory" (exit 4).
"""
import os
from typing import Any

import numpy as np
from scipy.sparse import csr_matrix

from ..runtime.errors import InputError
from ..runtime.limits import address_space_left, available_memory
from ..runtime.parallel import current_threads
from ..runtime.signals import deferred
from ..runtime.streams import held_c_stderr

ENV = "SRARAP_FACTOR"
#: what rslab's analysis takes per stored entry, with a margin (22 measured on a grid)
ANALYSIS_BYTES_PER_ENTRY = 64
#: the process that first used rslab (0: none): a child forked from it must not
_USED_IN = 0


def backend() -> str:
    """The factorization ``$SRARAP_FACTOR`` asks for: ``rslab`` or ``superlu`` for every
    matrix, ``auto`` (or unset: :func:`..linalg.factor` picks by size)."""
    asked = os.environ.get(ENV, "").strip().lower() or "auto"
    if asked not in ("auto", "rslab", "superlu"):
        raise InputError(f"{ENV}={os.environ[ENV]!r}: expected rslab, superlu or auto")
    return asked


def rslab_factor(A: csr_matrix, single: bool) -> Any:
    """rslab's factor of the symmetric positive definite ``A`` (double precision, or single
    if ``single``), or None where it cannot be relied on (see the module's docstring).

    Parameters
    ----------
    A : (n, n) sparse float matrix, symmetric
    single : bool, factor in single precision (half the memory; about 1e-5 relative accuracy)

    Returns
    -------
    rslab.Ldlt or None; its ``solve_many(B)`` takes and returns (n, k) float64 arrays
    """
    global _USED_IN
    if backend() == "superlu" or _USED_IN not in (0, os.getpid()) or \
            address_space_left() is not None:
        return None
    rslab = _module()
    if rslab is None:
        return None
    _USED_IN = os.getpid()
    dtype = "float32" if single else "float64"
    # the solve's thread count: rslab's factor is the same bit for bit at any count (its
    # documentation), and so are its solves (tests/test_parallel.py checks both)
    threads = current_threads()
    try:
        with held_c_stderr():
            A = A.astype(np.float64, copy=False)
            if not _room_for(ANALYSIS_BYTES_PER_ENTRY * A.nnz):  # its analysis allocates too
                return None
            plan = rslab.analyze(A, path="ldlt", ordering="amd", threads=threads,
                                 factor_dtype=dtype)
            need = plan.memory_plan(dtype, nrhs=4, threads=threads)["peak_bytes"]
            if not _room_for(need):  # SuperLU's turn, which says "out of memory" if it must
                return None
            f = plan.factor(A)
    except MemoryError:
        raise
    except Exception:  # noqa: BLE001 -- refused, for any reason: SuperLU's turn
        return None
    except BaseException as exc:  # a Rust panic (its threads) is a BaseException
        if type(exc).__name__ != "PanicException":
            raise
        return None
    return f if f.inertia == (A.shape[0], 0, 0) else None


def _room_for(need: int) -> bool:
    """Whether the memory there is (:func:`available_memory`: the system's, a container's)
    holds a plan of ``need`` bytes; one that does not is SuperLU's, which says "out of
    memory" where it must."""
    have = available_memory()
    return have is None or need <= have


def _module():
    try:
        with deferred():  # a compiled module: a signal in its initialization is held back
            import rslab
    except ImportError:
        return None
    return rslab


# Loaded here, by the thread that imports the solver (the main one): rslab brings its own
# allocator (mimalloc), which binds its main heap to the thread that loads the library.
# Loaded by the multiresolution setup's background thread, it crashed the process (SIGSEGV in
# ``mi_thread_init`` beside the simplification, every run from 20,000 vertices; or in the main
# thread's next solve after that thread had ended). Loading starts no thread: a process
# forked after it, and before rslab's first use, uses rslab as well.
_module()
