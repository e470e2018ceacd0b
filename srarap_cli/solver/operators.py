"""Edge weights, cell adjacency and the Laplacian of a triangle mesh."""
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..runtime.parallel import Blocks, blocks
from .group_rotations import label_sum
from .libigl import igl
from .linalg import fill_order

#: the edge weights :func:`cell_graph` computes (the settings table offers these)
WEIGHT_KINDS = ("cotan", "cotan-clamped", "uniform")

# Half-cotangents are bounded: an angle under ~0.06 degrees (a needle) would otherwise give
# a weight that swamps its neighbours and the conditioning of every solve.
MAX_HALF_COT = 500.0


@dataclass(frozen=True)
class CellGraph:
    """Directed one-ring edges of every vertex cell, with their weights.

    Attributes
    ----------
    I, J : (m,) int arrays
        Directed edge ``i -> j``; every undirected mesh edge appears once in each direction,
        sorted by ``I``.
    c : (m,) float array
        Symmetric edge weight ``c_ij`` (cotangent, clamped cotangent or 1).
    degree : (n,) int array
        Number of one-ring neighbours of each vertex.
    area : float
        Total surface area of the mesh.
    degenerate : int
        Triangle angles whose cotangent was not finite (zero-area faces); they count as 0.
    """

    I: np.ndarray
    J: np.ndarray
    c: np.ndarray
    degree: np.ndarray
    area: float
    degenerate: int = 0

    @property
    def n(self) -> int:
        return self.degree.shape[0]

    @property
    def laplacian(self) -> sp.csr_matrix:
        """``K = D - W`` with ``W_ij = c_ij``: (n, n), positive semi-definite,
        ``(K P)_i = sum_j c_ij (p_i - p_j)``. Made when asked for, not held: only setup steps
        ask (the Poisson matrix, connected parts, a transfer's factorization), and a held
        one stayed through every solve (0.12 GB at 1.2M vertices, made in 0.04 s there)."""
        # scipy takes 32-bit indices where they fit, as the matrix it was once built from
        W = sp.csr_matrix((self.c, self.J, self.indptr), shape=(self.n,) * 2)
        return (sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()

    @cached_property
    def _nested_order(self):
        # every mesh edge, zero weights included: the Laplacian drops the edges whose clamped
        # cotangent weight is 0 (right angles), and a dissection of that thinner graph leaves
        # the rotor matrix, which couples them, without separators (a subdivided cylinder:
        # 8 times the fill, 30 times the factor time)
        edges = sp.csr_matrix((np.ones(self.I.size), (self.I, self.J)), shape=(self.n,) * 2)
        return fill_order(edges)

    @cached_property
    def indptr(self) -> np.ndarray:
        """``(n + 1,)`` int array: vertex ``i``'s edges are ``indptr[i]:indptr[i + 1]``."""
        return np.concatenate([[0], np.cumsum(self.degree)])

    @cached_property
    def blocks(self) -> Blocks:
        """The per-iteration work's blocks for threads: (vertex range, its edges' range) pairs
        of :func:`~srarap_cli.runtime.parallel.blocks`, in order."""
        indptr, rows = self.indptr, blocks(self.n)
        return rows.carrying((r, slice(int(indptr[r.start]), int(indptr[r.stop])))
                             for r in rows)

    def fill_order(self, rows: np.ndarray | None = None) -> np.ndarray:
        """A fill-reducing order of the vertices ``rows`` (default all), as positions into
        ``rows``: METIS's nested dissection of the whole mesh graph, run once per graph and
        restricted to each matrix's vertices, so the Poisson matrix and the rotor
        preconditioner (whose free vertices differ) share one run (3.4 s at 738k vertices).
        Removing vertices keeps a nested dissection's separators separators."""
        order = self._nested_order
        if rows is None:
            return order
        rank = np.empty(self.n, dtype=np.int64)
        rank[order] = np.arange(self.n)
        return np.argsort(rank[rows], kind="stable")

    def edge_blocks(self, m: int | None = None) -> Blocks:
        """The ``edges`` blocks (:data:`~srarap_cli.runtime.parallel.PLANS`) of the first
        ``m`` (default all) edges: per-edge temporaries are made a block at a time (whole, a
        738k-vertex mesh's 4.4M directed edges made 0.1-0.3 GB of them at once in every
        iteration); meshes under ~40k vertices fit in one block, where the sums are those of
        a single pass."""
        return blocks(self.I.size if m is None else m, "edges")

    def cell_sum(self, values: np.ndarray, edges: slice = slice(None)) -> np.ndarray:
        """Sum per-edge ``values`` of shape (m, ...) into their source vertex: (n, ...);
        ``edges`` (a slice) says which edges ``values`` belong to (default all)."""
        flat = values.reshape(values.shape[0], -1)
        # I is sorted: the sums add each cell's edges in order, like a sparse incidence
        # product, without keeping that (n, m) matrix (53 MB at 738k vertices)
        sums = label_sum(flat, self.I[edges], self.n)
        return sums.reshape((self.n,) + values.shape[1:])


def row_views(A: sp.csr_matrix) -> Blocks:
    """``A``'s :func:`~srarap_cli.runtime.parallel.blocks` with their rows of ``A``,
    which share its values and indices (no copy).

    Built without scipy's constructor, whose format check copies a slice of less than half
    its array (``_prune_array``): every block was a copy (the 1.2M-vertex cylinder's operators,
    0.4 GB, held twice; its peak fell by 0.19 GB).

    Examples
    --------
    >>> A = sp.eye(40_000, format="csr")
    >>> [bool(np.shares_memory(B.data, A.data)) for rows, B in row_views(A)]
    [True, True, True]
    """
    rows_of_a = blocks(A.shape[0])
    out = []
    for rows in rows_of_a:
        lo, hi = int(A.indptr[rows.start]), int(A.indptr[rows.stop])
        block = sp.csr_matrix((rows.stop - rows.start, A.shape[1]), dtype=A.dtype)
        block.data, block.indices = A.data[lo:hi], A.indices[lo:hi]
        block.indptr = (A.indptr[rows.start:rows.stop + 1] - lo).astype(A.indices.dtype)
        out.append((rows, block))
    return rows_of_a.carrying(out)


def mesh_area(V: np.ndarray, F: np.ndarray) -> float:
    """Total surface area of a triangle mesh (zero-area faces count 0)."""
    return float(np.nansum(igl.doublearea(V, F)) / 2.0)


def cell_graph(V: np.ndarray, F: np.ndarray, weights: str = "cotan-clamped") -> CellGraph:
    """Build the cell graph of a triangle mesh.

    Parameters
    ----------
    V : (n, 3) float array
    F : (f, 3) int array
    weights : {"cotan", "cotan-clamped", "uniform"}
        ``cotan`` is ``(cot a + cot b) / 2``; ``cotan-clamped`` is ``max(0, cotan)`` as the
        reference implementation uses; ``uniform`` sets every weight to 1.

    Returns
    -------
    CellGraph

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> g = cell_graph(V, np.array([[0, 1, 2]]))
    >>> g.degree.tolist(), round(g.area, 3)
    ([2, 2, 2], 0.5)
    """
    if weights not in WEIGHT_KINDS:
        raise ValueError(f"weights must be one of {', '.join(WEIGHT_KINDS)}, not {weights!r}")
    n = V.shape[0]
    half_cot = igl.cotmatrix_entries(V, F)  # columns: edges opposite corners 0, 1, 2
    rows = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    cols = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    vals = half_cot.T.ravel()
    finite = np.isfinite(vals)
    vals = np.clip(np.where(finite, vals, 0.0), -MAX_HALF_COT, MAX_HALF_COT)
    W = sp.coo_matrix((np.concatenate([vals, vals]),
                       (np.concatenate([rows, cols]), np.concatenate([cols, rows]))),
                      shape=(n, n)).tocsr()
    W.sum_duplicates()
    W.sort_indices()
    if weights == "cotan-clamped":
        W.data = np.maximum(W.data, 0.0)
    elif weights == "uniform":
        W.data = np.ones_like(W.data)
    I = np.repeat(np.arange(n), np.diff(W.indptr))
    area = mesh_area(V, F)
    return CellGraph(I=I, J=W.indices.astype(np.int64), c=W.data.copy(),
                     degree=np.diff(W.indptr), area=area, degenerate=int((~finite).sum()))


def triangle_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Unnormalized normals of triangles ``F`` (t, 3) of ``V`` (n, 3): ``(b - a) x (c - a)``,
    twice each triangle's area long: (t, 3). Rows gathered with ``np.take`` and the cross
    product written out (``np.cross`` copies its inputs around): the same values, several
    times faster on millions of triangles.

    Examples
    --------
    >>> triangle_normals(np.eye(3), np.array([[0, 1, 2]])).tolist()
    [[1.0, 1.0, 1.0]]
    """
    a, b, c = (np.take(V, F[:, k], axis=0) for k in range(3))
    x, y = b - a, c - a
    return np.column_stack([x[:, 1] * y[:, 2] - x[:, 2] * y[:, 1],
                            x[:, 2] * y[:, 0] - x[:, 0] * y[:, 2],
                            x[:, 0] * y[:, 1] - x[:, 1] * y[:, 0]])
