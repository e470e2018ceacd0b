"""The ``srarap`` command group; each subcommand lives in its own module.

Subcommand modules are imported only when their command runs, so that ``srarap --help`` does
not load the numerical stack (about a second).

Rule: imports ``tasks``, ``io``, ``solver`` and ``runtime`` (the top layer: options, exit
codes, summaries); only ``srarap_cli.entry`` imports it.
"""
from .group import (
    COMMANDS,
    LazyGroup,
    main,
)

__all__ = ["COMMANDS", "LazyGroup", "main"]
