"""Choose, build and run a solver from settings: direct or multiresolution."""
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.warning_codes import note
from .deformer import Deformer
from .interface import Solver
from .multires.deformer import MultiresDeformer
from .multires.size import coarse_size
from .result import DeformResult
from .settings import Settings, with_keywords


def make_deformer(V: ArrayLike, F: ArrayLike, constrained: ArrayLike,
                  labels: ArrayLike | None = None, *, settings: Settings | None = None,
                  area: float | None = None, cache: str | None = None,
                  **options: Any) -> Solver:
    """The solver for ``settings``: a :class:`~srarap_cli.solver.deformer.Deformer`, or a
    :class:`~srarap_cli.solver.multires.MultiresDeformer` when ``multires`` asks for one.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array; constrained : (k,) int array
    labels : (k,) int array, optional, handle group of each constrained vertex
    settings : Settings, optional, every solver setting (default: the defaults); the
        solver keeps it, and its solve settings are what ``solve`` uses unless told otherwise
    area : float, optional, ``A`` of the energy (default: the mesh's area)
    cache : str, optional, folder for multiresolution coarse meshes
    **options : any solver setting by name, over ``settings``

    Returns
    -------
    Solver (see :mod:`srarap_cli.solver.interface`)
    """
    settings = with_keywords(settings, options, ("setup", "solve", "build"), "make_deformer")
    n = np.shape(V)[0]
    size = coarse_size(settings.multires, n)
    if size is None:
        deformer = Deformer(V, F, constrained, settings=settings, area=area, labels=labels)
        if settings.multires not in ("auto", "off"):
            deformer.warnings.append(note("multires-size", f"multires {settings.multires} is not "
                                          f"below the mesh's {n} vertices: solved directly"))
        return deformer
    return MultiresDeformer.or_direct(V, F, constrained, labels, settings=settings, size=size,
                                      cache=cache, area=area)


def deform_arrays(V: ArrayLike, F: ArrayLike, constrained: ArrayLike, targets: ArrayLike, *,
           initial: tuple[np.ndarray, np.ndarray] | None = None,
           callback: Callable[[dict], None] | None = None, cache: str | None = None,
           settings: Settings | None = None, **options: Any) -> DeformResult:
    """One-shot deformation: build the solver and solve once.

    Parameters
    ----------
    V : (n, 3) float array
    F : (f, 3) int array
    constrained : (k,) int array
    targets : (k, 3) float array
    initial : (positions, rotors), optional warm start
    callback : callable(dict), optional, receives each log row
    cache : str, optional, folder for multiresolution coarse meshes
    settings : Settings, optional, every solver setting (default: the CLI's defaults)
    **options : any solver setting of :mod:`srarap_cli.solver.settings` (``alpha``, ``tol``,
        ``time_limit``, ``multires``, ...), over ``settings``

    Returns
    -------
    DeformResult

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> r = deform_arrays(V, [[0, 1, 2], [1, 3, 2]], [0, 1, 2, 3], V + 1.0, time_limit=5)
    >>> r.converged, r.stop_reason.value
    (True, 'converged')
    """
    resolved = with_keywords(settings, options, ("setup", "solve", "build"), "deform")
    solver = make_deformer(V, F, constrained, settings=resolved, cache=cache)
    return solver.solve(targets, initial=initial, callback=callback)
