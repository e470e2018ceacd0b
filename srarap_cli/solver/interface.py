"""What every solver offers: the interface the tasks, the CLI and the API program against.

:class:`~srarap_cli.solver.deformer.Deformer` (one mesh) and
:class:`~srarap_cli.solver.multires.MultiresDeformer` (through a coarse mesh) both satisfy
:class:`Solver`; :func:`~srarap_cli.solver.oneshot.make_deformer` returns one or the other.
A test checks both against it, so a change to one ``solve`` signature cannot drift from the
other's.
"""
from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from .result import DeformResult
from .settings import Settings


@runtime_checkable
class Solver(Protocol):
    """A solver built once per mesh and constraint set, solved per target set.

    Attributes
    ----------
    settings : Settings, what it was built with (its solve settings are the default of
        each ``solve``)
    V : (n, 3) float array, rest positions; F : (f, 3) int array, triangles
    constrained : (k,) int array, the constrained vertex ids, in the order of ``targets``
    warnings : list of str, what the mesh or the constraints deserved a warning for
    """

    settings: Settings
    V: np.ndarray
    F: np.ndarray
    constrained: np.ndarray
    warnings: list[str]

    def solve(self, targets: ArrayLike, *,
              initial: tuple[np.ndarray, np.ndarray] | None = None,
              callback: Callable[[dict], None] | None = None,
              settings: Settings | None = None, start: str | None = None,
              **options: Any) -> DeformResult:
        """Deform toward ``targets`` (k, 3); see :meth:`Deformer.solve`. The result's
        ``stop_reason`` says why the solve stopped."""
        ...
