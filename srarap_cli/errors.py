"""Error types the CLI maps to exit codes; each message is one line naming file and field."""


class InputError(ValueError):
    """A mesh or handle file is unreadable or invalid."""


class OutputError(OSError):
    """An output file could not be written."""
