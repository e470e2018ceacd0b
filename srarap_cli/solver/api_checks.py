"""Checks at the Python API's boundary: a wrong argument is a ValueError that names it and the
expected shape, not a numpy broadcast error or a NumericalError deep inside a solve."""
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.limits import MAX_COORDINATE


def mesh_arrays(V: ArrayLike, F: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``V`` as an (n, 3) finite float array and ``F`` as an (f, 3) int array indexing it.

    Examples
    --------
    >>> mesh_arrays([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    Traceback (most recent call last):
    ...
    ValueError: F: vertex index 3 out of range for 3 vertices (ids are 0-based)
    """
    V = _floats(V, "V")
    if V.ndim != 2 or V.shape[1] != 3 or not len(V):
        raise ValueError(f"V must be an (n, 3) array of vertex positions, got shape {V.shape}")
    if not np.isfinite(V).all():
        raise ValueError("V has NaN or infinite coordinates")
    huge = np.abs(V).max(axis=1) > MAX_COORDINATE
    if huge.any():
        raise ValueError(f"V: vertex {int(np.flatnonzero(huge)[0])} has a coordinate beyond "
                         f"{MAX_COORDINATE:g} (its square would overflow); rescale the mesh")
    F = _array(F, "F")
    if F.ndim != 2 or F.shape[1] != 3 or not len(F):
        raise ValueError(f"F must be an (f, 3) array of triangles, got shape {F.shape}")
    if F.dtype.kind not in "iu":
        if F.dtype.kind != "f" or not np.all(F == np.round(F)):
            raise ValueError(f"F must hold integer vertex indices, got dtype {F.dtype}")
    _in_range(F, len(V), "F")
    return V, F.astype(np.int64, copy=False)  # no copy of an int64 F: 35 MB at 738k vertices


def positive(value: Any, name: str) -> float:
    """``value`` as a finite float > 0 (an area, a scale).

    Examples
    --------
    >>> positive(0, "area")
    Traceback (most recent call last):
    ...
    ValueError: area must be a finite number > 0, got 0
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def labels(values: ArrayLike, k: int) -> np.ndarray:
    """Group labels of the ``k`` constrained vertices as a (k,) int array of labels >= 0."""
    out = _array(values, "labels")
    if out.ndim != 1 or len(out) != k:
        raise ValueError(f"labels must be a 1-d array of {k} group labels, one per constrained "
                         f"vertex, got shape {out.shape}")
    if out.dtype.kind not in "iu" and not (out.dtype.kind == "f" and np.all(out == np.round(out))):
        raise TypeError(f"labels must hold integer group labels, got dtype {out.dtype}")
    if k and out.min() < 0:
        raise ValueError("labels must be >= 0")
    return out.astype(np.int64)


def _in_range(ids, n, name):
    """Refuse an index outside 0..n-1, named as given (before any cast: an unsigned 2**64-1
    would wrap to -1)."""
    low, high = ids.min(), ids.max()
    if low < 0 or high >= n:
        bad = low if low < 0 else high
        raise ValueError(f"{name}: vertex index {int(bad) if float(bad).is_integer() else bad} "
                         f"out of range for {n} vertices (ids are 0-based)")


def _array(values, name):
    """``np.asarray(values)``, a ragged nesting refused by name."""
    try:
        return np.asarray(values)
    except ValueError:
        raise ValueError(f"{name} must be a rectangular array (its rows have different "
                         "lengths)") from None


def vertex_ids(ids: ArrayLike, n: int, name: str = "constrained") -> np.ndarray:
    """``ids`` as a (k,) int array of distinct vertex indices below ``n``."""
    ids = _array(ids, name)
    if ids.dtype.kind not in "iu" or ids.ndim > 1:
        raise ValueError(f"{name} must be a 1-d array of integer vertex indices")
    if ids.size:
        _in_range(ids, n, name)
    ids = ids.astype(np.int64).ravel()
    if np.unique(ids).size != ids.size:
        raise ValueError(f"{name} lists a vertex twice")
    return ids


def targets(values: ArrayLike, k: int) -> np.ndarray:
    """``values`` as a (k, 3) finite float array, one row per constrained vertex."""
    values = _floats(values, "targets")
    if values.shape != (k, 3):
        raise ValueError(f"targets must be a ({k}, 3) array, one row per constrained vertex "
                         f"in the order given, got shape {values.shape}")
    if not np.isfinite(values).all():
        raise ValueError("targets has NaN or infinite values")
    if values.size and np.abs(values).max() > MAX_COORDINATE:  # a singular factor said so
        raise ValueError(f"targets has coordinates beyond {MAX_COORDINATE:g} (their squares "
                         "would overflow); rescale the mesh and the targets")
    return values


def initial(state: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A warm start ``(positions, rotors)`` as (n, 3) and (n, 4) finite float arrays (an
    earlier result of the same mesh)."""
    try:
        positions, rotors = state
    except (TypeError, ValueError):
        raise ValueError("initial must be a pair (positions, rotors), such as an earlier "
                         "result's (result.positions, result.rotors)") from None
    out = []
    for values, name, width in ((positions, "positions", 3), (rotors, "rotors", 4)):
        values = _floats(values, f"initial {name}")
        if values.shape != (n, width):
            raise ValueError(f"initial {name} must be a ({n}, {width}) array, one row per "
                             f"vertex, got shape {values.shape}")
        if not np.isfinite(values).all():
            raise ValueError(f"initial {name} has NaN or infinite values")
        out.append(values)
    return out[0], out[1]


def _floats(values, name):
    values = _array(values, name)
    if np.iscomplexobj(values):  # a cast to float would drop the imaginary parts in silence
        raise ValueError(f"{name} must hold real numbers, got complex ones")
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of numbers") from None


def mesh_like(mesh: Any, name: str = "mesh") -> tuple[np.ndarray, Any]:
    """``(V, F)`` arrays of whatever the ecosystem calls a mesh, without importing its package.

    Accepts a ``(V, F)`` pair, srarap's :class:`~srarap_cli.io.mesh.Mesh`, a
    ``meshio.Mesh`` (``points`` and triangle or quad ``cells``; quads split in two), and
    anything with ``vertices`` and ``faces`` arrays (``trimesh.Trimesh``, ``open3d``'s
    ``TriangleMesh`` after ``np.asarray``). Raises TypeError naming ``name`` otherwise.

    Examples
    --------
    >>> V, F = mesh_like(([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]))
    >>> V.shape, F.tolist()
    ((3, 3), [[0, 1, 2]])
    >>> mesh_like("bunny.obj")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    TypeError: mesh must be a (V, F) pair, ... got str (read a file with srarap_cli.read_mesh)
    """
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return mesh_arrays(*mesh)
    if hasattr(mesh, "face_sizes") and hasattr(mesh, "triangles"):  # srarap's own Mesh
        return mesh_arrays(mesh.vertices, mesh.triangles()[0])
    if hasattr(mesh, "points") and hasattr(mesh, "cells"):  # meshio.Mesh
        return mesh_arrays(mesh.points[:, :3] if np.ndim(mesh.points) == 2 else mesh.points,
                           _meshio_triangles(mesh.cells, name))
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        return mesh_arrays(np.asarray(mesh.vertices), np.asarray(mesh.faces))
    hint = " (read a file with srarap_cli.read_mesh)" if isinstance(mesh, (str, bytes)) or \
        hasattr(mesh, "__fspath__") else ""
    raise TypeError(f"{name} must be a (V, F) pair, a trimesh.Trimesh, a meshio.Mesh or an "
                    f"object with vertices and faces arrays, got {type(mesh).__name__}{hint}")


def _meshio_triangles(cells, name):
    parts = []
    for block in cells:
        data = np.asarray(block.data)
        if block.type == "triangle":
            parts.append(data)
        elif block.type == "quad":
            parts += [data[:, [0, 1, 2]], data[:, [0, 2, 3]]]
    if not parts:
        raise ValueError(f"{name}: the meshio.Mesh has no triangle or quad cells")
    return np.vstack(parts)
