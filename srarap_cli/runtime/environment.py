"""Environment variables changed for a block, as they were after it."""
import contextlib
import os
from collections.abc import Iterator, Mapping


@contextlib.contextmanager
def environ_changed(changes: Mapping[str, str | None]) -> Iterator[None]:
    """``os.environ`` with ``changes`` inside the block (None removes a variable); every
    variable named is as it was after it. For what a started process inherits: a fork
    server's thread settings, a library's leftover variables kept from new workers.

    Examples
    --------
    >>> with environ_changed({"SRARAP_EXAMPLE": "1"}):
    ...     os.environ["SRARAP_EXAMPLE"]
    '1'
    >>> "SRARAP_EXAMPLE" in os.environ
    False
    """
    before = {name: os.environ.get(name) for name in changes}
    _apply(changes)
    try:
        yield
    finally:
        _apply(before)


def _apply(values):
    for name, value in values.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value
