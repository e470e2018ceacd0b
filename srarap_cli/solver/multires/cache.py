"""Coarse meshes cached on disk, keyed by what they depend on."""
import hashlib
import io
import os
from collections.abc import Sequence

import numpy as np

from ...runtime.commit import atomic_write
from ...runtime.errors import OutputError, excerpt
from ...runtime.warning_codes import as_note, note
from .simplify import CoarseMesh, simplify_to_subset

#: Names the entry layout and the simplifier's behaviour: change it when either changes.
FORMAT = "srarap-coarse-2"


def cache_key(V: np.ndarray, F: np.ndarray, size: int, groups: Sequence[np.ndarray]) -> str:
    """Hex digest of the mesh, the wanted size, the constrained groups and the simplifier."""
    h = hashlib.sha256()
    for part in (FORMAT, str(int(size)), str(len(groups))):
        h.update(part.encode() + b"\0")
    for array in (np.ascontiguousarray(V, dtype="<f8"), np.ascontiguousarray(F, dtype="<i8"),
                  *(np.ascontiguousarray(g, dtype="<i8") for g in groups)):
        h.update(str(array.shape).encode())
        h.update(array.tobytes())
    return h.hexdigest()


def coarse_mesh(V: np.ndarray, F: np.ndarray, size: int, groups: list[np.ndarray],
                cache_dir: str | None = None) -> tuple[CoarseMesh, bool, list[str]]:
    """:func:`simplify_to_subset`, through ``cache_dir`` when given.

    Returns
    -------
    coarse : CoarseMesh
    hit : bool, read from the cache
    notes : list of str, cache problems (never fatal: the mesh is simplified again)
    """
    if cache_dir is None:
        return simplify_to_subset(V, F, size, groups), False, []
    path = os.path.join(cache_dir, cache_key(V, F, size, groups) + ".npz")
    notes: list[str] = []
    if os.path.exists(path):
        try:
            with np.load(path) as z:
                found = CoarseMesh(z["vertices"], z["faces"],
                                   [as_note(str(w)) for w in z["warnings"]])
            if _consistent(found, len(V)):
                return found, True, []
            notes.append(note("cache-entry", f"{path}: inconsistent cache entry, simplifying again"))
        except (OSError, ValueError, KeyError) as exc:
            notes.append(note("cache-entry",
                              f"{path}: unreadable cache entry ({exc}), simplifying again"))
    coarse = simplify_to_subset(V, F, size, groups)
    try:
        os.makedirs(cache_dir, exist_ok=True)
        buf = io.BytesIO()
        np.savez(buf, vertices=coarse.vertices, faces=coarse.faces,
                 warnings=np.array(coarse.warnings, dtype=str))
        atomic_write(path, buf.getvalue())
    except (OSError, OutputError) as exc:
        notes.append(note("cache-unwritable", f"{excerpt(cache_dir, 80)}: cannot write the cache "
                          f"({excerpt(exc, 120)})"))
    except RecursionError:  # os.makedirs recurses once per missing folder level
        notes.append(note("cache-unwritable", f"{excerpt(cache_dir, 80)}: cannot write the "
                          "cache (too many folder levels)"))
    return coarse, False, notes


def _consistent(coarse, n):
    v, f = coarse.vertices, coarse.faces
    return (v.ndim == 1 and v.size > 0 and np.all(np.diff(v) > 0) and v[0] >= 0 and v[-1] < n
            and f.ndim == 2 and f.shape[1] == 3 and f.min(initial=0) >= 0
            and f.max(initial=0) < v.size)
