"""What compiled libraries print on the process's own stderr (file descriptor 2).

SuperLU prints a failed allocation itself ("malloc fails for local dworkptr[]."), beside the
one line srarap reports. While a factorization runs, descriptor 2 is therefore pointed at a
temporary file (:func:`held_c_stderr`); the hold is process-wide, so whoever reports an
error first puts descriptor 2 back (:func:`release`): a factorization in a background thread
must not swallow the main thread's error line.
"""
import contextlib
import os
import tempfile
import threading
from collections.abc import Iterator

_lock = threading.Lock()
_held: dict[object, tuple] = {}  # token -> (saved descriptor, temporary file); at most one active at a time


@contextlib.contextmanager
def held_c_stderr() -> Iterator[None]:
    """Hold back what C code writes to descriptor 2 inside the block: written out after it
    when the block succeeds, dropped when it raises (srarap then reports the failure in its
    own line). A block entered while another holds passes through."""
    token = object()
    with _lock:
        if _held:
            token = None
        else:
            try:
                saved, held = os.dup(2), tempfile.TemporaryFile()
                os.dup2(held.fileno(), 2)
                _held[token] = (saved, held)
            except OSError:  # no descriptor to spare: let the library print as it will
                token = None
    ok = False
    try:
        yield
        ok = True
    finally:
        if token is not None:
            _end(token, keep=ok)


def release() -> None:
    """Put descriptor 2 back now, dropping what was held (called before an error line)."""
    with _lock:
        tokens = list(_held)
    for token in tokens:
        _end(token, keep=False)


def _end(token, keep):
    with _lock:
        entry = _held.pop(token, None)
        if entry is None:
            return
        saved, held = entry
        os.dup2(saved, 2)
        os.close(saved)
    if keep:
        held.seek(0)
        text = held.read()
        if text:
            with contextlib.suppress(OSError):
                os.write(2, text)
    held.close()
