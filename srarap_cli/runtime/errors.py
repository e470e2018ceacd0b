"""Error types the CLI maps to exit codes; each message is one line naming file and field."""
import difflib
from collections.abc import Iterable


class InputError(ValueError):
    """A mesh or handle file is unreadable or invalid."""


class OutputError(OSError):
    """An output file could not be written."""


class NumericalError(RuntimeError):
    """The solve produced non-finite values."""


class SingularSystemError(RuntimeError):
    """A factorization met a singular matrix (degenerate geometry)."""


class UsageProblem(ValueError):
    """Options that do not go together (``--ascii`` for a format without a text variant):
    exit code 2, as the command line's own usage errors."""


def unknown_key(key: object, allowed: Iterable[str], where: str) -> str:
    """The message for a key ``where`` does not take, with the nearest allowed key as a hint.

    Examples
    --------
    >>> unknown_key("fixd", ["fixed", "box", "rotate"], "group 'base'")
    "unknown key 'fixd' in group 'base'; did you mean 'fixed'? (allowed: box, fixed, rotate)"
    """
    allowed = sorted(allowed)
    close = difflib.get_close_matches(str(key), allowed, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"unknown key {excerpt(key)!r} in {where}{hint} (allowed: {', '.join(allowed)})"


def excerpt(text: object, limit: int = 40) -> str:
    """A short, printable excerpt of user-supplied text for an error message (the file
    could be anything, a symlinked system file included: quote little of it).

    Examples
    --------
    >>> excerpt("root:x:0:0:root:/root:/bin/bash" * 3)
    'root:x:0:0:root:/root:/bin/bashroot:x...'
    """
    text = "".join(c if c.isprintable() else "?" for c in str(text))
    return text if len(text) <= limit else text[:limit - 3] + "..."
