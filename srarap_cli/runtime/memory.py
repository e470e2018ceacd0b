"""Peak resident memory per stage of a run, for ``-v`` and the large-mesh benchmark, without
touching what the kernel reports of the process (``/usr/bin/time``, ``ru_maxrss``).

Linux keeps one high-water mark per process (``VmHWM``), which only grows here: srarap never
resets it (``/proc/self/clear_refs`` would, and then ``/usr/bin/time`` reported half the peak
a run needed). A stage during which the mark rose set a new peak of the process, and that
mark is its peak; a stage that stayed below an earlier one's is measured by sampling the
resident size (``VmRSS``) every few milliseconds while it is open, so a short spike within
it can go unseen (its figure is then a little low). The kernel counts resident pages per
CPU and folds them in batches, so either figure can be a few pages off (256 KB on 2 cores;
a ``VmHWM`` read later can sit below a ``VmRSS`` sampled earlier). Stages nest (a coarse
level's setup inside the fine level's): each figure is the highest resident size seen
between its start and its end, whatever opened or closed inside. Elsewhere (no ``/proc``)
every figure is None.

Measuring is off until :func:`enable` (``-v`` turns it on): the sampling thread runs only
while a stage is open.
"""
import itertools
import os
import threading

_STATUS = "/proc/self/status"
#: seconds between samples of the resident size while a stage is open
EVERY = 0.005
_open: dict[int, tuple[int, int]] = {}  # token -> (the mark at its start, the highest seen)
_ids = itertools.count()
_lock = threading.Lock()
_wake = threading.Condition(_lock)
_enabled = False
_sampler: tuple[int, threading.Thread] | None = None  # its process (a fork has none)


def enable() -> None:
    """Measure from now on."""
    global _enabled
    _enabled = True


def status_bytes(field: str) -> int | None:
    """A size from ``/proc/self/status`` in bytes (``"VmHWM"``, ``"VmSize"``), or None where
    it cannot be read."""
    key = field.encode() + b":"
    try:
        with open(_STATUS, "rb") as f:
            for line in f:
                if line.startswith(key):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _high_water():
    return status_bytes("VmHWM")


def _sample():
    """Fold the resident size into every open stage (with ``_lock`` held)."""
    rss = status_bytes("VmRSS")
    if rss is not None:
        for token, (mark, seen) in _open.items():
            _open[token] = (mark, max(seen, rss))


def _run_sampler():
    with _wake:
        while True:
            while not _open:
                _wake.wait()
            _sample()
            _wake.wait(EVERY)


def start() -> int | None:
    """Open a stage; returns its token (None where peaks cannot be measured, or measuring
    is not enabled)."""
    global _sampler
    with _lock:
        mark = _high_water() if _enabled else None
        if mark is None:
            return None
        token = next(_ids)
        _open[token] = (mark, 0)
        _sample()
        if _sampler is None or _sampler[0] != os.getpid():
            thread = threading.Thread(target=_run_sampler, name="srarap-memory", daemon=True)
            thread.start()
            _sampler = (os.getpid(), thread)
        _wake.notify()
        return token


def stop(token: int | None) -> int | None:
    """Close the stage ``token``: its peak resident memory in bytes (None: not measured)."""
    if token is None:
        return None
    with _lock:
        _sample()
        mark, seen = _open.pop(token, (None, None))
        if mark is None:
            return None
        now = _high_water()
        return max(seen, now) if now is not None and now > mark else seen


def gigabytes(peaks: dict[str, int | None]) -> str:
    """``setup 2.91 GB, iterations 3.02 GB``: the measured stages of ``peaks``, in order."""
    return ", ".join(f"{name} {value / 1e9:.2f} GB" for name, value in peaks.items()
                     if value is not None)
