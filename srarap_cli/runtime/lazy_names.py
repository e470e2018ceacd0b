"""A package whose names are imported on first use: its ``__init__`` holds a table of names
and the modules that define them, and :func:`lazy_getattr` makes its module ``__getattr__``.
Nothing is imported with the package (a command pays only for what it uses), and two packages
that use each other's names never meet half-initialized."""
import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_getattr(package: str, where: Mapping[str, str]) -> Callable[[str], Any]:
    """The module ``__getattr__`` of ``package``: ``name`` from its module ``where[name]``
    (relative to the package), imported on first use; AttributeError for another name."""
    def __getattr__(name: str) -> Any:
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f".{where[name]}", package), name)
    return __getattr__
