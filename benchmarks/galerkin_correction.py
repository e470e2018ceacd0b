"""Experiment (issue 51, item 4): a coarse-grid correction with a Galerkin coarse operator, a
Newton step on the energy over smooth fields, in place of the shipped full approximation
scheme (``srarap_cli/solver/multires/correction.py``). Not shipped: see "A Galerkin coarse
operator" in docs/background/performance.md for what it gained and what it cost.
``install()`` makes every MultiresDeformer use it (``multires_error_split.py --galerkin``).

Run: python benchmarks/galerkin_correction.py [--cases spot46k,cylinder1m] [--aggregates N]
(whole solves, shipped then Galerkin, and how far apart they end)

Started from the coarse solution, the full-resolution iteration still converges slowly in
the smooth components of its error (more than 99.9% of it; see the performance page). Those
are what a coarse space can hold: with ``P`` (n, m) a smooth prolongation from ``m``
aggregates of vertices, the correction is the Newton step of the energy restricted to
``x + P z`` for the positions and the rotors' increments,

    (P^T Q P) z = -P^T g,

``Q`` half the energy's Hessian (``srarap_cli.solver.hessian``), ``g`` half its gradient
(zero in the positions, which the global step left at their minimum). ``P^T Q P`` is the fine
operator seen through ``P``, in the fine problem's units by construction: the coarse mesh's
own energy (the shipped full approximation scheme) contracts smooth errors faster than the
full mesh's iteration does, and its corrections removed 13-26% of the smooth error on the
46k Spot; these remove 54-89% there.

``P`` is smoothed aggregation: the aggregates' indicator functions after one damped Jacobi
sweep of the cotangent Laplacian, so that a correction ramps over a ring of vertices at an
aggregate's border instead of jumping (with the indicators alone, ``P^T Q P`` is too stiff
and its corrections removed 35-50%).

The Hessian changes little over the full-resolution iterations (their start is already close
to the answer), so ``P^T Q P`` is assembled and factored once per solve, at its first
correction; each correction after costs a gradient (one pass over the edges) and one solve of
the coarse factor. Measured on the 46k Spot, the same factor for all corrections or a fresh
one each time: the same iterations and gains.

The Newton step heads for the energy's minimum, the local/global iteration for its own fixed
point, which can sit above it (2.5e-5 relative on a bar twisted 200 degrees): there a
correction never vanishes, the energy goes down with each correction and up with the steps
between, and the stopping test never passes (1,000 iterations). A correction that is not
``SHRINK`` times the one before (after one more try with a fresh operator) therefore ends the
corrections of a solve.
"""
from typing import Any

import numpy as np
import scipy.sparse as sp

from srarap_cli.solver.hessian import energy_hessian, rotor_gradient
from srarap_cli.solver.linalg import _rslab_solver, factor
from srarap_cli.solver.one_triangle import rslab_factor
from srarap_cli.solver.quaternion import from_rotation_vectors, multiply
from srarap_cli.solver.state import State

#: a correction that is not this much smaller than the one before ends the corrections of
#: a solve (see the module's text)
SHRINK = 0.5
#: aggregates at most: a coarse mesh with more vertices lends its own coarse mesh's cells
#: (the coarse operator has 6 unknowns an aggregate, and its factor grows faster than that)
MAX_AGGREGATES = 20_000
#: damping of the prolongation's smoothing sweep (smoothed aggregation's usual 2/3)
OMEGA = 2.0 / 3.0


class CoarseSpace:
    """The smooth fields a correction moves in: the prolongation and what of the coarse
    operator does not depend on the state. Built once per full-resolution mesh.

    Parameters
    ----------
    graph : CellGraph of the full mesh
    cells : (n,) int array, each vertex's aggregate (0 to m - 1; -1 for none)
    fixed : (j,) int array, vertices whose position is held

    Attributes
    ----------
    m : int, aggregates
    """

    def __init__(self, graph: Any, cells: np.ndarray, fixed: np.ndarray) -> None:
        n, self.m = graph.n, int(cells.max(initial=-1)) + 1
        inside = np.flatnonzero(cells >= 0)
        P0 = sp.csr_matrix((np.ones(inside.size), (inside, cells[inside])), shape=(n, self.m))
        K = graph.laplacian
        diagonal = K.diagonal()
        damping = np.divide(OMEGA, diagonal, out=np.zeros(n), where=diagonal > 0)
        P = (P0 - sp.diags(damping) @ (K @ P0)).tocsr()
        free = np.ones(n)
        free[fixed] = 0.0
        Pu = (sp.diags(free) @ P).tocsr()
        self._P3, self._Pu3 = _blocked(P), _blocked(Pu)
        self._uu = _blocked((2.0 * (Pu.T @ (K @ Pu))).tocsr())
        self._pattern = _BlockPattern(graph)

    def prolong(self, z: np.ndarray) -> np.ndarray:
        """Coarse values (m, 3) on every vertex: (n, 3)."""
        return (self._P3 @ z.ravel()).reshape(-1, 3)

    def restrict(self, v: np.ndarray) -> np.ndarray:
        """``P^T v`` for vertex values ``v`` (n, 3): (m, 3)."""
        return (self._P3.T @ v.ravel()).reshape(-1, 3)

    def operator(self, H: Any) -> sp.csr_matrix:
        """``P^T Q P`` (6m, 6m) for half the Hessian ``H``; aggregate ``a``'s position
        increments are rows ``6a`` to ``6a + 2``, its rotors' ``6a + 3`` to ``6a + 5``."""
        ww_diagonal, ww_edges, wu_diagonal, wu_edges = H.blocks(self._pattern.reverse)
        ww = self._P3.T @ (self._pattern.matrix(ww_diagonal, ww_edges) @ self._P3)
        wu = self._P3.T @ (self._pattern.matrix(wu_diagonal, wu_edges) @ self._Pu3)
        parts = [(self._uu, 0, 0), (wu, 3, 0), (wu.T, 0, 3), (ww, 3, 3)]
        rows, cols, vals = [], [], []
        for part, row, col in parts:
            coo = part.tocoo()
            rows.append(6 * (coo.row // 3) + coo.row % 3 + row)
            cols.append(6 * (coo.col // 3) + coo.col % 3 + col)
            vals.append(coo.data)
        size = 6 * self.m
        A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(size, size))
        A.eliminate_zeros()
        return A


class GalerkinCorrection:
    """The correction of one solve's full-resolution iterates (its targets): a Newton step
    over :class:`CoarseSpace`, with the coarse operator of the first corrected iterate.

    Parameters
    ----------
    space : CoarseSpace
    step : LocalGlobalStep of the full mesh, for the targets

    Attributes
    ----------
    every : int, a correction every ``every`` iterations, from the first
    """

    every = 2

    def __init__(self, space: CoarseSpace, step: Any) -> None:
        self.space, self.step = space, step
        self._solve: Any = None
        self._kept: np.ndarray | None = None
        self._last, self._done = float("inf"), False

    def due(self, iteration: int) -> bool:
        """Whether the iterate numbered ``iteration`` (from 1) gets a correction."""
        return not self._done and (iteration - 1) % self.every == 0

    def __call__(self, state: State, residual: np.ndarray) -> np.ndarray | None:
        """The correction (n, 4) to add to the rotors of the iterate after ``state``
        (whose positions are the global step's for its rotors); None when there is none.
        ``residual`` (the step's rotors minus the state's) is not used: the gradient says
        more."""
        fresh = self._solve is None
        w = self._newton(state, fresh)
        if _size(w) > SHRINK * self._last and not fresh:
            w = self._newton(state, True)  # the operator may be stale: once more
        if _size(w) > SHRINK * self._last:
            self._done = True
            return None
        self._last = _size(w)
        return multiply(from_rotation_vectors(w), state.rotors) - state.rotors

    def _newton(self, state, fresh):
        """The rotor increments (n, 3) of the Newton step over the coarse space (None if not
        finite), with the coarse operator of ``state`` when ``fresh``."""
        d = self.step.deformer
        P, R = state.positions, state.rotors
        if fresh:
            self._factor(energy_hessian(d.graph, d.edges, P, R, d.bending_weight))
        assert self._kept is not None
        m = self.space.m
        rhs = np.zeros((m, 6))
        rhs[:, 3:] = -self.space.restrict(rotor_gradient(d.graph, d.edges, P, R, d.bending_weight))
        z = np.zeros(6 * m)
        z[self._kept] = self._solve(rhs.ravel()[self._kept])
        w = self.space.prolong(z.reshape(m, 6)[:, 3:])
        return w if np.isfinite(w).all() else None

    def _factor(self, H):
        A = self.space.operator(H)
        self._kept = np.flatnonzero(np.diff(A.indptr) > 0)
        A = A[self._kept][:, self._kept]
        # one factor a solve, which its few solves do not repay: rslab's (two times faster
        # than SuperLU's on the 46k Spot's) in single precision (0.49 -> 0.32 s there); a
        # Newton step needs no more digits. SuperLU where rslab refuses (not positive definite)
        scale = float(abs(A).max())
        ldlt = rslab_factor(A / scale, single=True)
        self._solve = (factor(A, symmetric=True) if ldlt is None
                       else _rslab_solver(ldlt, scale, single=True))


class _BlockPattern:
    """The 3x3-block sparsity of a per-vertex operator on the mesh graph: a block per
    directed edge and one per vertex, in block-CSR order."""

    def __init__(self, graph: Any) -> None:
        n, E = graph.n, graph.I.size
        rows = np.concatenate([graph.I, np.arange(n)])
        cols = np.concatenate([graph.J, np.arange(n)])
        order = np.lexsort((cols, rows))
        slot = np.empty_like(order)
        slot[order] = np.arange(order.size)
        self._edges, self._diagonal = slot[:E], slot[E:]
        self._indices = cols[order]
        self._indptr = np.searchsorted(rows[order], np.arange(n + 1))
        self._n = n
        key = graph.I * n + graph.J
        by_key = np.argsort(key)
        self.reverse = by_key[np.searchsorted(key[by_key], graph.J * n + graph.I)]

    def matrix(self, diagonal: np.ndarray, edges: np.ndarray) -> sp.bsr_matrix:
        data = np.empty((self._indices.size, 3, 3))
        data[self._diagonal], data[self._edges] = diagonal, edges
        return sp.bsr_matrix((data, self._indices, self._indptr), shape=(3 * self._n,) * 2)


def _size(w):
    """The largest rotor increment of ``w`` (inf for None: no step)."""
    return np.inf if w is None else float(np.abs(w).max(initial=0.0))


def _blocked(M):
    """``M`` (a, b) times the 3x3 identity, block by block: (3a, 3b) in 3x3 blocks."""
    return sp.bsr_matrix(sp.kron(M, sp.eye(3), format="bsr"), blocksize=(3, 3))


def aggregates(md: Any) -> np.ndarray:
    """Each vertex's aggregate for a refine-mode MultiresDeformer: its coarse vertex's cell,
    or where the coarse mesh has more than :data:`MAX_AGGREGATES` vertices, the cell of that
    vertex's own coarse vertex, and so on down the levels."""
    from srarap_cli.solver.multires import MultiresDeformer

    cells, level = md._nearest, md
    while (level.coarse.vertices.size > MAX_AGGREGATES
           and isinstance(level.coarse_deformer, MultiresDeformer)):
        level = level.coarse_deformer
        cells = np.where(cells >= 0, level._nearest[np.maximum(cells, 0)], -1)
    return cells


def install() -> None:
    """Every MultiresDeformer's full-resolution iterations (at every level) corrected by a
    :class:`GalerkinCorrection` instead of the shipped one."""
    from srarap_cli.solver.multires import MultiresDeformer

    def coarse_correction(md, targets, tol=None):
        tol = md.settings.tol if tol is None else tol
        space = md.__dict__.get("_galerkin_space")
        if space is None:
            space = md.__dict__["_galerkin_space"] = CoarseSpace(
                md.fine.graph, aggregates(md), md.fine.fixed)
        return GalerkinCorrection(space, md.fine.step_for(targets, tol))

    MultiresDeformer.coarse_correction = coarse_correction


def _run(name, galerkin):
    """One default solve of a benchmark case (those of ``multires_error_split.py``)."""
    import time

    from error_split_cases import case as _case

    from srarap_cli.io.handles import load_handles
    from srarap_cli.io.mesh import read_mesh
    from srarap_cli.solver.oneshot import make_deformer
    from srarap_cli.solver.settings import resolve
    from srarap_cli.tasks.pipeline import problem

    mesh_path, handles_path = _case(name)
    mesh = read_mesh(mesh_path)
    handles = load_handles(handles_path, mesh.vertices)
    p = problem(mesh, handles, mesh_path)
    start = time.perf_counter()
    d = make_deformer(p.V, p.F, p.ids, settings=resolve(handles.solver))
    setup, start = time.perf_counter() - start, time.perf_counter()
    r = d.solve(p.targets)
    label = "Galerkin" if galerkin else "shipped"
    print(f"{name} {label}: setup {setup:.1f} s, solve {time.perf_counter() - start:.1f} s, "
          f"{r.iterations} iterations (+ {r.multires.iterations} coarse), energy "
          f"{r.energy:.10g}, {r.stop_reason}; stages " + ", ".join(
              f"{k} {v:.1f}" for k, v in r.multires.stages.items()), flush=True)
    return r


def main():
    """Whole solves, the shipped correction then this one (one process each would be
    fairer to memory; the times are the solves'), and how far apart their shapes end."""
    import argparse

    ap = argparse.ArgumentParser(description=main.__doc__.splitlines()[0])
    ap.add_argument("--cases", default="cylinder1m")
    ap.add_argument("--aggregates", type=int, default=None, help="MAX_AGGREGATES")
    args = ap.parse_args()
    if args.aggregates:
        globals()["MAX_AGGREGATES"] = args.aggregates
    for name in args.cases.split(","):
        shipped = _run(name, False)
        install()
        ours = _run(name, True)
        P = shipped.positions
        diagonal = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
        far = float(np.sqrt(np.einsum("ij,ij->i", ours.positions - P, ours.positions - P).max()))
        print(f"{name}: energies {(ours.energy - shipped.energy) / shipped.energy:+.1e} apart "
              f"(relative), shapes {far / diagonal:.1e} of the diagonal", flush=True)


if __name__ == "__main__":
    import os
    import sys

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    main()
