"""The one-shot function of the Python API: any mesh, any handles, one deformation."""
from collections.abc import Callable
from dataclasses import replace
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike

from ..io.handles import as_constraints
from ..io.mesh.mesh import Mesh
from ..solver.api_checks import mesh_like
from ..solver.oneshot import deform_arrays
from ..solver.result import DeformResult
from ..solver.settings import STAGES, Settings, keywords, resolve
from .pipeline import deform_mesh


@overload
def deform(mesh: Any, handles: Any, /, *, callback: Callable[[dict], None] | None = None,
           cache: str | None = None, settings: Settings | None = None,
           **options: Any) -> DeformResult: ...


@overload
def deform(V: ArrayLike, F: ArrayLike, constrained: ArrayLike, targets: ArrayLike, /,
           *, callback: Callable[[dict], None] | None = None, cache: str | None = None,
           initial: tuple[np.ndarray, np.ndarray] | None = None,
           settings: Settings | None = None, **options: Any) -> DeformResult: ...


def deform(mesh: Any, handles: Any, /, *arrays: Any,
           callback: Callable[[dict], None] | None = None, cache: str | None = None,
           initial: tuple[np.ndarray, np.ndarray] | None = None,
           settings: Settings | None = None, **options: Any) -> DeformResult:
    """Deform a mesh by its handles, in one call.

    Two forms (typed as two overloads): ``deform(mesh, handles, **settings)`` and the array
    form ``deform(V, F, constrained, targets, initial=None, **settings)``; the first two
    arguments are positional in both (a setting can then never collide with their names).

    Parameters
    ----------
    mesh : a ``(V, F)`` pair, a :class:`~srarap_cli.io.mesh.Mesh` (from
        :func:`~srarap_cli.io.mesh.read_mesh` or ``Mesh.from_arrays``), a ``trimesh.Trimesh``,
        a ``meshio.Mesh``, or anything with ``vertices`` and ``faces`` arrays
    handles : a handle file's path, a dict in the handle-file schema (``{"groups": ...}``),
        or an ``(ids, targets)`` pair: (k,) vertex ids and their (k, 3) target positions
    callback : callable(dict), optional, receives each log row
    cache : str, optional, folder for multiresolution coarse meshes
    settings : Settings, optional, the base (default: the defaults) that a handle file's
        ``solver`` section and the keywords apply over
    **options : solver settings by name (``alpha``, ``tol``, ``max_iter``, ``multires``,
        ...), over the handle file's

    Returns
    -------
    DeformResult
        With ``faces`` set: ``result.to_arrays()``, ``result.to_trimesh()``,
        ``result.to_meshio()``; ``result.warnings`` lists what the input deserved a warning
        for.

    Notes
    -----
    The array form ``deform(V, F, constrained, targets, initial=..., ...)`` of
    :func:`srarap_cli.solver.oneshot.deform_arrays` is accepted too (a warm start needs it, or a
    :class:`~srarap_cli.solver.deformer.Deformer`).

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> r = deform((V, [[0, 1, 2], [1, 3, 2]]), ([0, 1, 2, 3], V + 1.0))
    >>> r.converged, r.to_arrays()[1].shape
    (True, (2, 3))
    """
    if len(arrays) == 2:
        return deform_arrays(mesh, handles, *arrays, initial=initial, callback=callback,
                             cache=cache, settings=settings, **options)
    if arrays:
        raise TypeError("deform() takes (mesh, handles) or (V, F, constrained, targets), "
                        f"got {2 + len(arrays)} positional arguments")
    if initial is not None:
        raise TypeError("deform(mesh, handles) starts cold; for a warm start use "
                        "deform(V, F, constrained, targets, initial=...) or a Deformer")
    given = keywords(options, STAGES, "deform")
    arrays = mesh_like(mesh)  # checked whatever its type: a NaN is the mesh's, not a handle's
    source = mesh if isinstance(mesh, Mesh) else Mesh.from_arrays(*arrays)
    constraints = as_constraints(handles, source.vertices)
    opts = resolve(settings or {}, constraints.solver, given)
    _, result, notes = deform_mesh(source, constraints, opts, callback=callback, cache=cache)
    return replace(result, faces=source.triangles()[0], warnings=list(notes))
