"""What a bounded child runs (:mod:`.bounded`; forked here, by :mod:`.child_server`, or
a fresh interpreter): the call under its memory bound, its answer pickled to its parent;
what its forker imports first (:func:`imported`), and how the parent waits on it
(:func:`readable`)."""
import importlib
import os
import pickle
import select
import signal
from collections.abc import Callable, Sequence
from typing import Any


def run_child(write: int, func: Callable[..., Any], args: tuple, memory: int | None) -> None:
    """In the child: ``func(*args)`` with ``memory`` bytes of address space beyond what the
    child holds now (None: no bound), its result or exception pickled to the descriptor
    ``write``; then the child ends (this never returns)."""
    code = 0
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, signal.SIG_DFL)
        _limit_memory(memory)
        try:
            out = ("ok", func(*args))
        except MemoryError as exc:
            out = ("memory", str(exc))
        except Exception as exc:  # noqa: BLE001 -- carried to the parent, raised there
            out = ("error", exc)
        try:
            data = pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # noqa: BLE001 -- an exception that does not pickle
            data = pickle.dumps(("error", RuntimeError(f"{type(exc).__name__}: {exc}")))
        with os.fdopen(write, "wb") as out_file:
            out_file.write(data)
    except BaseException:  # noqa: BLE001 -- the child ends here whatever happened
        code = 1
    finally:
        os._exit(code)


def _limit_memory(memory: int | None) -> None:
    if memory is None:
        return
    import resource

    now = _address_space_used()
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    want = now + memory
    if hard != resource.RLIM_INFINITY:
        want = min(want, hard)
    if soft == resource.RLIM_INFINITY or want < soft:
        resource.setrlimit(resource.RLIMIT_AS, (want, hard))


def _address_space_used() -> int:
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def readable(fd: int, seconds: float | None) -> bool:
    """Whether ``fd`` is readable (a pipe with data or closed, a pidfd whose process ended)
    within ``seconds`` (None: wait as long as it takes). ``poll``, not ``select``: a
    process with over 1,024 open files (a batch's threads) gets larger descriptors."""
    poller = select.poll()
    poller.register(fd, select.POLLIN)
    return bool(poller.poll(None if seconds is None else int(seconds * 1000) + 1))


def imported(modules: Sequence[str]) -> None:
    """Import ``modules`` here, so that a child forked later starts with them (one that
    fails to import is left to the child, whose error then says why)."""
    for name in modules:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 -- the child meets it again and reports it
            continue
