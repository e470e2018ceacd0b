"""Error types the CLI maps to exit codes; each message is one line naming file and field."""
import difflib
import re
from collections.abc import Iterable

#: CPython's refusal of an integer of too many digits, with its advice to the programmer
TOO_MANY_DIGITS = re.compile(r"Exceeds the limit \((\d+) digits\) for integer string "
                             r"conversion[^;]*?: value has (\d+) digits; use "
                             r"sys\.set_int_max_str_digits\(\) to increase the limit")
#: a value a library quotes back, too long for one line of ours
LONG_QUOTE = re.compile(r"'([^'\n]{61,})'")


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


def plain(message: str) -> str:
    """A library's ``message`` fit for one line of ours: a number of too many digits said as
    that (not as Python's advice to raise a limit), a value quoted back cut to 60 characters.

    Examples
    --------
    >>> plain("Exceeds the limit (4300 digits) for integer string conversion: value has "
    ...       "5000 digits; use sys.set_int_max_str_digits() to increase the limit")
    'a number of 5000 digits (at most 4300)'
    >>> plain("'" + "1" * 500 + "' is not a valid integer")
    "'11111111111111111111111111111111111111111111111111111111...' is not a valid integer"
    """
    message = TOO_MANY_DIGITS.sub(lambda m: f"a number of {m[2]} digits (at most {m[1]})",
                                  message)
    return LONG_QUOTE.sub(lambda m: repr(excerpt(m[1], 60)), message)
