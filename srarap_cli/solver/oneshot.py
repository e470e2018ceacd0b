"""Choose, build and run a solver from settings: direct or multiresolution."""
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .deformer import Deformer, DeformResult
from .multires import MultiresDeformer, coarse_size
from .settings import DEFAULT_SETTINGS, check_keywords


def make_deformer(V: ArrayLike, F: ArrayLike, constrained: ArrayLike,
                  labels: ArrayLike | None = None, *, area: float | None = None,
                  cache: str | None = None, **options: Any) -> Deformer | MultiresDeformer:
    """The solver for the settings ``options``: a :class:`Deformer`, or a
    :class:`MultiresDeformer` when ``multires`` asks for one.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array; constrained : (k,) int array
    labels : (k,) int array, optional, handle group of each constrained vertex
    area : float, optional, ``A`` of the energy (default: the mesh's area)
    cache : str, optional, folder for multiresolution coarse meshes
    **options : setup and build settings (see :mod:`srarap_cli.solver.settings`)
    """
    check_keywords(options, ("setup", "build"), "make_deformer")
    settings = DEFAULT_SETTINGS.replace(**options)
    setup = settings.stage("setup")
    setting = settings.multires
    size = coarse_size(setting, np.shape(V)[0])
    if size is None:
        deformer = Deformer(V, F, constrained, area=area, labels=labels, **setup)
        if setting not in (None, "auto", "off"):
            deformer.warnings.append(f"multires {setting} is not below the mesh's "
                                     f"{np.shape(V)[0]} vertices: solved directly")
        return deformer
    return MultiresDeformer.or_direct(V, F, constrained, labels, size=size, cache=cache, area=area,
                            mode=settings.multires_mode,
                            **setup)


def deform(V: ArrayLike, F: ArrayLike, constrained: ArrayLike, targets: ArrayLike, *,
           initial: tuple[np.ndarray, np.ndarray] | None = None,
           callback: Callable[[dict], None] | None = None, cache: str | None = None,
           **settings: Any) -> DeformResult:
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
    **settings : any solver setting of :mod:`srarap_cli.solver.settings` (``alpha``, ``tol``,
        ``time_limit``, ``multires``, ...); the defaults are the CLI's

    Returns
    -------
    DeformResult

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> r = deform(V, [[0, 1, 2], [1, 3, 2]], [0, 1, 2, 3], V + 1.0, time_limit=5)
    >>> r.converged
    True
    """
    check_keywords(settings, ("setup", "build", "solve"), "deform")
    resolved = DEFAULT_SETTINGS.replace(**settings)
    deformer = make_deformer(V, F, constrained, cache=cache, **resolved.stage("setup", "build"))
    return deformer.solve(targets, initial=initial, callback=callback, **resolved.stage("solve"))
