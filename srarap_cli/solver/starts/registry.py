"""The starts by name, and how to add one."""
from collections.abc import Callable

from .harmonic import harmonic_start
from .laplacian import laplacian_start
from .warm import extrapolated_start, warm_start

STARTS: dict[str, Callable] = {"harmonic": harmonic_start, "laplacian": laplacian_start, "warm": warm_start,
          "extrapolated": extrapolated_start}
#: the starts that take the caller's ``initial``; ``warm`` is the default one
WARM_STARTS = ("warm", "extrapolated")


def register(name: str, start: Callable) -> None:
    """Make ``start`` available as ``Deformer.solve(..., start=name)``."""
    STARTS[name] = start
