"""Mesh problems the solve survives, reported as warnings with counts."""

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from ..runtime.warning_codes import note
from .libigl import igl
from .operators import triangle_normals

NEEDLE_DEGREES = 1.0


def solvable_faces(F: np.ndarray) -> np.ndarray:
    """Triangles without a repeated vertex (those have no area and no edge to speak of):
    ``F`` itself when every one qualifies (a copy would live as long as the solve)."""
    keep = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])
    if not keep.all():
        return F[keep]
    out = F.view()
    out.flags.writeable = False  # the caller's faces: nothing downstream may write them
    return out


def geometry_problem(V: np.ndarray, F: np.ndarray) -> str | None:
    """Why the triangles F of V cannot be solved in double precision, or None.

    Examples
    --------
    >>> geometry_problem(np.array([[0., 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1, 2]]))
    'every triangle has zero area (collinear or coincident vertices)'
    """
    F = solvable_faces(np.asarray(F))
    if not len(F):
        return "no triangle has three distinct vertices"
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True  # not np.unique: a sort of every corner (0.5 s at 2.5M faces)
    diag = float(np.linalg.norm(np.ptp(V[used], axis=0)))
    if not 1e-100 < diag < 1e100:
        return (f"its vertices span {diag:.3g}: too small or too large to solve in double "
                "precision; rescale the mesh")
    area = np.linalg.norm(triangle_normals(V, F), axis=1)
    if np.all(area <= 1e-14 * diag * diag):
        return "every triangle has zero area (collinear or coincident vertices)"
    return None


def unique_rows(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct rows of an int array (m, k) in lexicographic order, and how often each occurs.

    Same result as ``np.unique(a, axis=0, return_counts=True)``, several times faster on
    millions of rows (no structured-dtype sort).

    Examples
    --------
    >>> rows, counts = unique_rows(np.array([[1, 2], [0, 5], [1, 2]]))
    >>> rows.tolist(), counts.tolist()
    ([[0, 5], [1, 2]], [1, 2])
    """
    a = np.asarray(a)
    if len(a) == 0:
        return a.reshape(0, a.shape[1] if a.ndim == 2 else 0), np.zeros(0, dtype=np.int64)
    s = a[np.lexsort(a.T[::-1])]
    start = np.flatnonzero(np.concatenate([[True], np.any(s[1:] != s[:-1], axis=1)]))
    return s[start], np.diff(np.append(start, len(s)))


def edge_adjacency(F: np.ndarray, n: int) -> csr_matrix:
    """(n, n) sparse matrix with every edge of ``F`` (f, 3) in one direction at least, for
    undirected graph algorithms (``csgraph`` with ``directed=False``): half the entries of
    the symmetric matrix (2.5M faces: built and its components found in 0.27 s, not 0.49).

    Examples
    --------
    >>> from scipy.sparse import csgraph
    >>> A = edge_adjacency(np.array([[0, 1, 2], [3, 4, 5]]), 7)
    >>> csgraph.connected_components(A, directed=False)[1].tolist()
    [0, 0, 0, 1, 1, 1, 2]
    """
    F = np.asarray(F)
    return sp.csr_matrix((np.ones(F.size), (F.ravel(), F[:, [1, 2, 0]].ravel())), shape=(n, n))


def distinct_ids(ids: np.ndarray, n: int) -> np.ndarray:
    """The distinct values of ``ids`` (any shape, all in ``0..n-1``), sorted: what
    ``np.unique`` gives, by one pass over a mask of ``n`` instead of a hash or sort of the ids
    (a 1.2M-vertex mesh's faces: 7.4M ids, about 0.6 s by ``np.unique``).

    Examples
    --------
    >>> distinct_ids(np.array([[3, 1, 2], [2, 1, 0]]), 5).tolist()
    [0, 1, 2, 3]
    """
    mask = np.zeros(n, dtype=bool)
    mask[np.asarray(ids).ravel()] = True
    return np.flatnonzero(mask)


def edge_counts(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges (e, 2) of triangles F (sorted pairs, in lexicographic order) and how
    many triangles hold each.

    Examples
    --------
    >>> edges, counts = edge_counts(np.array([[0, 1, 2], [2, 1, 3]]))
    >>> edges.tolist(), counts.tolist()
    ([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [1, 1, 2, 1, 1])
    """
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    a, b = F.ravel(), F[:, [1, 2, 0]].ravel()
    n = int(F.max(initial=-1)) + 1
    # summing duplicates sorts only each row's few entries: several times faster than a
    # lexicographic sort of every pair on millions of edges
    A = sp.csr_matrix((np.ones(a.size, dtype=np.int64), (np.minimum(a, b), np.maximum(a, b))),
                      shape=(n, n))
    A.sum_duplicates()
    low = np.repeat(np.arange(n), np.diff(A.indptr))
    return np.stack([low, A.indices.astype(np.int64)], axis=1), A.data


def mesh_warnings(V: np.ndarray, F: np.ndarray,
                  edges: tuple[np.ndarray, np.ndarray] | None = None) -> list[str]:
    """Warning lines for duplicate faces, collapsed, zero-area and needle triangles,
    non-manifold edges and vertices, and surfaces cut open at coincident vertices, of a
    triangle mesh (V (n, 3), F (f, 3)). ``edges``: :func:`edge_counts` of ``F`` where the
    caller has it (used when no face is collapsed or repeated, the usual case).

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> mesh_warnings(V, np.array([[0, 1, 2], [2, 0, 1]]))
    ['1 duplicate faces (same vertices as another face) [duplicate-faces]']
    """
    out: list[str] = []
    collapsed = len(F) - len(solvable_faces(F))
    if collapsed:
        out.append(note("collapsed-faces", f"{collapsed} faces repeat a vertex; left out of the solve"))
    F = solvable_faces(F)
    distinct = unique_rows(np.sort(F, axis=1))[0]
    duplicates = len(F) - len(distinct)
    if duplicates:
        out.append(note("duplicate-faces",
                        f"{duplicates} duplicate faces (same vertices as another face)"))
    scale = float(np.ptp(V, axis=0).max()) ** 2 if len(V) else 0.0
    area2 = igl.doublearea(V, F)
    zero = ~(area2 > 1e-14 * scale)
    if zero.any():
        out.append(note("zero-area", f"{int(zero.sum())} zero-area faces; their edges get no "
                        "weight from them"))
    with np.errstate(invalid="ignore"):
        angles = np.degrees(igl.internal_angles(V, F[~zero])) if (~zero).any() else np.zeros((0, 3))
    needles = int((angles.min(axis=1, initial=180) < NEEDLE_DEGREES).sum()) if len(angles) else 0
    if needles:
        out.append(note("needles", f"{needles} needle faces (an angle under {NEEDLE_DEGREES:g} "
                        "degree); cotangents are capped at 1000 so no edge weight can swamp "
                        "the others"))
    if edges is None or collapsed or duplicates:
        edges = edge_counts(distinct)  # duplicates said above
    out.extend(_manifold_warnings(distinct, len(V), edges[1]))
    out.extend(_unwelded_warnings(V, *edges))
    return out


def _unwelded_warnings(V, edges, counts):
    """Border vertices that sit exactly on another border vertex: the surface is cut open
    there (each side deforms on its own), typically a triangle soup or a file split at
    texture seams by the program that loaded it. Only border vertices can be such cuts, so
    a closed mesh costs one pass over its edges."""
    border = np.unique(edges[counts == 1])
    if border.size < 2:
        return []
    _, first, count = np.unique(V[border], axis=0, return_index=True, return_counts=True)
    extra = int(border.size - first.size)
    if not extra:
        return []
    return [note("coincident-vertices",
                 f"{extra} vertices sit exactly on another vertex ({int((count > 1).sum())} "
                 "positions): the faces there share no vertex, so the surface is cut open; "
                 "weld coincident vertices first (trimesh: merge_vertices(merge_tex=True, "
                 "merge_norm=True))")]


def _manifold_warnings(F, n, counts):
    out: list[str] = []
    if (counts > 2).any():
        out.append(note("non-manifold", f"{int((counts > 2).sum())} non-manifold edges (more "
                        "than two faces); solved, the operators are defined there"))
    bad = int((fans_per_vertex(F, n) > 1).sum())
    if bad:
        out.append(note("non-manifold", f"{bad} non-manifold vertices (faces around them form "
                        "several fans); solved"))
    return out


def fans_per_vertex(F: np.ndarray, n: int) -> np.ndarray:
    """How many fans the faces around each vertex form: groups of faces joined through the
    edges at the vertex. A vertex is manifold (libigl's ``is_vertex_manifold``) when the
    count is one; this count takes one sparse matrix and one connected-components pass, four
    to six times faster than libigl on a million vertices.

    Each side of a corner, the directed edge from the corner's vertex to one of its face's
    other two, is a node; the two sides of a corner are linked, and equal sides are one node,
    so the components at a vertex are its fans.

    Parameters
    ----------
    F : (f, 3) int array, triangles without repeated vertices
    n : int, number of vertices

    Returns
    -------
    (n,) int array, 0 for vertices no face uses

    Examples
    --------
    >>> bowtie = np.array([[0, 1, 2], [0, 3, 4]])  # two triangles touching at vertex 0
    >>> fans_per_vertex(bowtie, 5).tolist()
    [2, 1, 1, 1, 1]
    """
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    corner, k = F.ravel(), F.size
    if not k:
        return np.zeros(n, dtype=np.int64)
    rows = np.concatenate([corner, corner])
    cols = np.concatenate([F[:, [1, 2, 0]].ravel(), F[:, [2, 0, 1]].ravel()])
    sides = sp.csr_matrix((np.ones(rows.size, dtype=np.int64), (rows, cols)), shape=(n, n))
    sides.sum_duplicates()
    sides.data = np.arange(sides.nnz, dtype=np.int64)
    node = np.asarray(sides[rows, cols]).ravel()
    links = sp.csr_matrix((np.ones(k, dtype=np.int8), (node[:k], node[k:])),
                          shape=(sides.nnz,) * 2)
    count, label = connected_components(links, directed=False)
    owner = np.empty(count, dtype=np.int64)
    owner[label] = np.repeat(np.arange(n), np.diff(sides.indptr))
    return np.bincount(owner, minlength=n)
