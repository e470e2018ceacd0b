"""Checks at the Python API's boundary: a wrong argument is a ValueError that names it and the
expected shape, not a numpy broadcast error or a NumericalError deep inside a solve."""
import numpy as np


def mesh_arrays(V, F):
    """``V`` as an (n, 3) finite float array and ``F`` as an (f, 3) int array indexing it.

    Examples
    --------
    >>> mesh_arrays([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])
    Traceback (most recent call last):
    ...
    ValueError: F: vertex index 3 out of range for V of 3 rows
    """
    V = _floats(V, "V")
    if V.ndim != 2 or V.shape[1] != 3 or not len(V):
        raise ValueError(f"V must be an (n, 3) array of vertex positions, got shape {V.shape}")
    if not np.isfinite(V).all():
        raise ValueError("V has NaN or infinite coordinates")
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3 or not len(F):
        raise ValueError(f"F must be an (f, 3) array of triangles, got shape {F.shape}")
    if F.dtype.kind not in "iu":
        if F.dtype.kind != "f" or not np.all(F == np.round(F)):
            raise ValueError(f"F must hold integer vertex indices, got dtype {F.dtype}")
    F = F.astype(np.int64, copy=False)  # no copy of an int64 F: 35 MB at 738k vertices
    if F.min() < 0 or F.max() >= len(V):
        bad = int(F.min() if F.min() < 0 else F.max())
        raise ValueError(f"F: vertex index {bad} out of range for V of {len(V)} rows")
    return V, F


def vertex_ids(ids, n, name="constrained"):
    """``ids`` as a (k,) int array of distinct vertex indices below ``n``."""
    ids = np.asarray(ids)
    if ids.dtype.kind not in "iu" or ids.ndim > 1:
        raise ValueError(f"{name} must be a 1-d array of integer vertex indices")
    ids = ids.astype(np.int64).ravel()
    if ids.size and (ids.min() < 0 or ids.max() >= n):
        raise ValueError(f"{name}: vertex index out of range for {n} vertices")
    if np.unique(ids).size != ids.size:
        raise ValueError(f"{name} lists a vertex twice")
    return ids


def targets(values, k):
    """``values`` as a (k, 3) finite float array, one row per constrained vertex."""
    values = _floats(values, "targets")
    if values.shape != (k, 3):
        raise ValueError(f"targets must be a ({k}, 3) array, one row per constrained vertex "
                         f"in the order given, got shape {values.shape}")
    if not np.isfinite(values).all():
        raise ValueError("targets has NaN or infinite values")
    return values


def _floats(values, name):
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of numbers") from None
