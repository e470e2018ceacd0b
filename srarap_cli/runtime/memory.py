"""Peak resident memory per stage of a run, for ``-v`` and the large-mesh benchmark.

Linux keeps one high-water mark per process (``VmHWM``) and lets a process reset it
(``/proc/self/clear_refs``); ``ru_maxrss`` only ever grows, so it cannot say which stage set
it. Stages nest (a coarse level's setup inside the fine level's), so a reset folds the mark
reached so far into every stage still open before clearing it: each stage's figure is the
highest resident size between its start and its end, whatever opened or closed inside.
Elsewhere (no ``/proc``) every figure is None.

Measuring is off until :func:`enable` (``-v`` turns it on): the reset also lowers what the
kernel reports as the process's peak afterwards (``ru_maxrss``, ``/usr/bin/time``'s maximum
resident size cover only the time since the last reset), which a run not asking for these
figures must not have changed under it.
"""
import itertools
import threading

_STATUS = "/proc/self/status"
_CLEAR = "/proc/self/clear_refs"
_open: dict[int, int] = {}
_ids = itertools.count()
_lock = threading.Lock()
_enabled = False


def enable() -> None:
    """Measure from now on (see the module's note on what the reset changes)."""
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


def _reset():
    try:
        with open(_CLEAR, "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _fold():
    mark = _high_water()
    if mark is not None:
        for token in _open:
            _open[token] = max(_open[token], mark)


def start() -> int | None:
    """Open a stage; returns its token (None where peaks cannot be measured, or measuring
    is not enabled)."""
    with _lock:
        if not _enabled or _high_water() is None:
            return None
        _fold()
        if not _reset():
            return None
        token = next(_ids)
        _open[token] = 0
        _fold()
        return token


def stop(token: int | None) -> int | None:
    """Close the stage ``token``: its peak resident memory in bytes (None: not measured)."""
    if token is None:
        return None
    with _lock:
        _fold()
        return _open.pop(token, None)


def gigabytes(peaks: dict[str, int | None]) -> str:
    """``setup 2.91 GB, iterations 3.02 GB``: the measured stages of ``peaks``, in order."""
    return ", ".join(f"{name} {value / 1e9:.2f} GB" for name, value in peaks.items()
                     if value is not None)
