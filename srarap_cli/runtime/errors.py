"""Error types the CLI maps to exit codes; each message is one line naming file and field."""


class InputError(ValueError):
    """A mesh or handle file is unreadable or invalid."""


class OutputError(OSError):
    """An output file could not be written."""


class NumericalError(RuntimeError):
    """The solve produced non-finite values."""


class SingularSystemError(RuntimeError):
    """A factorization met a singular matrix (for example a part with no constraint)."""


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
