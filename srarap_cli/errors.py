"""Error types the CLI maps to exit codes; each message is one line naming file and field."""


class InputError(ValueError):
    """A mesh or handle file is unreadable or invalid."""


class OutputError(OSError):
    """An output file could not be written."""


class NumericalError(RuntimeError):
    """The solve produced non-finite values."""


class SingularSystemError(RuntimeError):
    """A factorization met a singular matrix (for example a part with no constraint)."""
