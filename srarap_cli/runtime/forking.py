"""When srarap forks: the one policy for every child process it starts.

A fork copies only the thread that makes it. A lock another thread held at that moment (a
host's thread: a test runner's, a notebook's, a Dask worker's; a pool of srarap's own) stays
held in the child, which then waits on it forever; Python 3.12 warns on such forks. So
srarap forks only where this process runs a single thread (all of its threads, not only
Python's: :func:`alone`), and where it does not, what the child was for decides
(:func:`how`):

============  ===================================================  ======  =========
need          for                                                  alone   otherwise
============  ===================================================  ======  =========
``bound``     a third-party reader under a time and memory bound   fork    fresh
``beside``    work apart only so that it runs side by side (an     fork    here
              animation's frames, a second file read while the
              first is)
``gil``       a call that holds the GIL for seconds while this     here    fresh
              process's other threads work (METIS beside the
              simplification)
``workers``   a batch's worker processes                           fork    fresh
============  ===================================================  ======  =========

``fresh`` is a new interpreter: for workers, a fork server started fresh, which forks
them; for ``bound`` work, the child server (:mod:`.child_server`), one kept for the
process, which forks each call. ``SRARAP_BOUNDED=0`` (or a platform without ``os.fork``) runs ``bound`` and
``beside`` work here, unbounded.
"""
import os
import threading

ENV_OFF = "SRARAP_BOUNDED"
NEEDS = ("bound", "beside", "gil", "workers")


def how(need: str) -> str:
    """``fork``, ``fresh`` or ``here``: how work of ``need`` (one of :data:`NEEDS`, see the
    module's table) runs now.

    Examples
    --------
    >>> how("gil") in ("here", "fresh")
    True
    """
    if need not in NEEDS:
        raise ValueError(f"need must be one of {NEEDS}, not {need!r}")
    forks = hasattr(os, "fork")
    if need in ("bound", "beside") and (not forks or os.environ.get(ENV_OFF) == "0"):
        return "here"
    single = forks and alone()
    if need == "gil":
        return "here" if single else "fresh"
    if single:
        return "fork"
    return "here" if need == "beside" else "fresh"


def alone() -> bool:
    """Whether this process runs a single thread (:func:`threads`).

    Examples
    --------
    >>> import threading
    >>> done = threading.Event()
    >>> helper = threading.Thread(target=done.wait)
    >>> helper.start()
    >>> alone()
    False
    >>> done.set(); helper.join()
    """
    return threads() == 1


def threads() -> int:
    """How many threads this process runs (all of them, not only Python's; where that is
    unknown, one more than Python's: never taken for a single thread)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return threading.active_count() + 1
