"""The drivers by name, and how to add one."""
from collections.abc import Callable
from functools import partial

from .anderson import anderson_iteration
from .plain import plain_iteration

DRIVERS: dict[str, Callable] = {"plain": plain_iteration, "anderson": anderson_iteration}
#: the drivers that take a multiresolution solve's coarse-grid corrections (``correction=``)
CORRECTED: set[str] = {"anderson"}
#: the ``accel`` setting's values and the driver each one names
ACCEL_DRIVERS = {"anderson": "anderson", "none": "plain"}


def register(name: str, driver: Callable, corrected: bool = False) -> None:
    """Make ``driver`` available as ``Deformer.solve(..., driver=name)``; ``corrected``: it
    takes a ``correction=`` keyword (coarse-grid corrections, applied to its iterates)."""
    DRIVERS[name] = driver
    if corrected:
        CORRECTED.add(name)


def corrected_driver(accel: str, correction: object) -> Callable | None:
    """The driver ``accel`` names with ``correction`` bound where it takes one, else None
    (the solve's own driver: it runs uncorrected)."""
    name = ACCEL_DRIVERS[accel]
    return partial(DRIVERS[name], correction=correction) if name in CORRECTED else None
