"""The drivers by name, and how to add one."""
from collections.abc import Callable

from .anderson import anderson_iteration
from .plain import plain_iteration

DRIVERS: dict[str, Callable] = {"plain": plain_iteration, "anderson": anderson_iteration}


def register(name: str, driver: Callable) -> None:
    """Make ``driver`` available as ``Deformer.solve(..., driver=name)``."""
    DRIVERS[name] = driver
