"""Deformer: precompute once per mesh and constraint set, then solve for any targets."""
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csgraph

from .energy import (
    accurate_enough,
    bending_energy,
    membrane_energy,
    membrane_from_covariance,
)
from .global_step import PoissonSolver
from .local_step import METHODS
from .operators import cell_graph
from .quaternion import IDENTITY, to_matrix
from .rest_edges import RestEdges

LOG_FIELDS = ("iteration", "membrane", "bending", "total", "rel_change", "max_move", "seconds")


class NumericalError(RuntimeError):
    """The solve produced non-finite values."""


@dataclass
class DeformResult:
    """Outcome of :meth:`Deformer.solve`.

    Attributes
    ----------
    positions : (n, 3) float array
    rotors : (n, 4) float array, unit quaternions (w, x, y, z) of the vertex cells
    log : list of dict, one per iteration (0 is the Laplacian-editing start), keys LOG_FIELDS
    converged : bool, relative energy change fell below ``tol``
    iterations : int, local/global iterations run
    full_energy : dict or None
        ``membrane``, ``bending``, ``total`` of the returned positions and rotors when they
        differ from the last log row (multiresolution: the log follows the coarse mesh)
    stages : dict, seconds per stage of a multiresolution solve (empty otherwise)
    coarse : dict or None, multiresolution only: ``vertices`` (coarse count), ``of`` (the
        solved mesh's count) and ``cache_hit`` (the coarse mesh came from the cache)
    """

    positions: np.ndarray
    rotors: np.ndarray
    log: list = field(default_factory=list)
    converged: bool = False
    iterations: int = 0
    full_energy: dict = None
    stages: dict = field(default_factory=dict)
    coarse: dict = None

    def energies(self):
        """``membrane``, ``bending`` and ``total`` energy of the returned shape."""
        source = self.log[-1] if self.full_energy is None else self.full_energy
        return {k: source[k] for k in ("membrane", "bending", "total")}

    @property
    def energy(self):
        return self.energies()["total"]


class Deformer:
    """SR-ARAP deformation of one triangle mesh with one set of constrained vertices.

    Builds the edge weights, factors the Poisson matrix and lays out the rotor system once;
    :meth:`solve` then runs the local/global iteration for any target positions.

    Parameters
    ----------
    V : (n, 3) float array, rest positions
    F : (f, 3) int array, triangles
    constrained : (k,) int array, ids of vertices whose positions are prescribed
    alpha : float > 0, bending weight (energy uses ``alpha * area``)
    feedback : float >= 0, pull of each rotor toward its previous value (paper's eps)
    weights : {"cotan-clamped", "cotan", "uniform"}
    area : float, optional; ``A`` in the energy, default the surface area of (V, F)
    method : {"sr-linear-sym", "sr-linear", "sr-relax", "arap"}
        Local step: the symmetric total-energy variant of the paper's one-solve system (the
        default: fastest to a given energy on the benchmarks), the paper's system itself,
        per-cell relaxation sweeps, or classic ARAP (no bending term).
    sweeps : int, relaxation sweeps per iteration for ``sr-relax``

    Attributes
    ----------
    auto_fixed : (j,) int array
        Vertices kept at rest because nothing could move them: unreferenced vertices and
        every connected part that holds no constrained vertex.
    warnings : list of str

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> F = np.array([[0, 1, 2], [1, 3, 2]])
    >>> d = Deformer(V, F, constrained=[0, 1, 2, 3])
    >>> r = d.solve(V + [0, 0, 1])
    >>> r.converged, np.allclose(r.positions, V + [0, 0, 1])
    (True, True)
    """

    def __init__(self, V, F, constrained, *, alpha=0.14, feedback=0.2,
                 weights="cotan-clamped", area=None, method="sr-linear-sym", sweeps=2):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
        if not alpha > 0:
            raise ValueError("alpha must be > 0")
        if not feedback >= 0:
            raise ValueError("feedback must be >= 0")
        self.V = np.asarray(V, dtype=float)
        self.F = np.asarray(F, dtype=np.int64)
        self.weights = weights
        self.graph = cell_graph(self.V, self.F, weights)
        self.alpha = float(alpha)
        self.area = self.graph.area if area is None else float(area)
        self.constrained = np.asarray(constrained, dtype=np.int64).ravel()
        mask = np.zeros(len(self.V), dtype=bool)
        mask[self.constrained] = True
        self.warnings = weight_warnings(self.graph)
        self.auto_fixed, notes = unanchored(self.graph, mask)
        self.warnings += notes
        mask[self.auto_fixed] = True
        self._fixed = np.flatnonzero(mask)
        self._slot = np.searchsorted(self._fixed, self.constrained)
        self.edges = RestEdges(self.graph, self.V)
        self._energy_floor = 1e-14 * max(float(self.graph.c @ self.edges.q_sq), 1e-300)
        self.poisson = PoissonSolver(self.graph, mask)
        step_class = METHODS[method]
        extra = {"sweeps": sweeps} if method == "sr-relax" else {}
        self.method = method
        self.local_step = step_class(self.edges, mask, self.alpha * self.area, feedback, **extra)
        self._bending_alpha = self.alpha if step_class.bending else 0.0

    def _fixed_targets(self, targets):
        full = self.V[self._fixed].copy()
        full[self._slot] = targets
        return full

    def solve(self, targets, *, max_iter=200, tol=1e-6, initial=None, callback=None,
              time_limit=None):
        """Deform toward ``targets`` for the constrained vertices.

        Parameters
        ----------
        targets : (k, 3) float array, in the order of ``constrained``
        max_iter : int >= 0, local/global iterations at most
        tol : float, stop when ``|E_k - E_{k-1}| <= tol * E_{k-1}``
        initial : (positions (n, 3), rotors (n, 4)), optional warm start; default is
            Laplacian editing (identity rotors, one Poisson solve)
        callback : callable(dict), called with each log row
        time_limit : float, optional; stop (not converged) once this many seconds have passed

        Returns
        -------
        DeformResult
        """
        start = time.perf_counter()
        targets = np.asarray(targets, dtype=float).reshape(-1, 3)
        fixed_targets = self._fixed_targets(targets)
        poisson = self.poisson.bind(fixed_targets)
        if initial is None:
            R = np.tile(IDENTITY, (len(self.V), 1))
            P = poisson(self.edges.rotated_divergence(R))
        else:
            P = np.array(initial[0], dtype=float)
            R = np.array(initial[1], dtype=float)
            P[self._fixed] = fixed_targets
        result = DeformResult(P, R)
        state = self._state(P, R)
        self._record(result, state, None, tol, start, callback)
        for k in range(1, max_iter + 1):
            R = self.local_step.step(state["S"], state["s"], R)
            Rm = to_matrix(R)
            P_new = poisson(self.edges.rotated_divergence(R, Rm))
            state = self._state(P_new, R, Rm)
            row = self._record(result, state, P, tol, start, callback)
            P = P_new
            result.iterations = k
            if row["rel_change"] <= tol:
                result.converged = True
                break
            if time_limit is not None and row["seconds"] >= time_limit:
                break
        result.positions, result.rotors = P, R
        return result

    def _state(self, P, R, Rm=None):
        """What an iteration knows about positions ``P`` with rotors ``R``: covariances (the
        next local step's input; per-cell stretch only for the steps that use it), the total
        stretch (for the energy) and rotation matrices."""
        S = self.edges.cross(P)
        if self.local_step.needs_stretch:
            s = self.edges.stretch(P)
            total = float(s.sum())
        else:
            s, total = None, self.edges.stretch_total(P)
        return {"P": P, "R": R, "S": S, "s": s, "stretch_total": total,
                "Rm": to_matrix(R) if Rm is None else Rm}

    def _membrane(self, st, tol):
        """Membrane energy from the covariances when that is accurate enough for ``tol``,
        else from the per-edge residuals (near-rigid shapes, ``tol`` 0)."""
        fast = membrane_from_covariance(st["S"], st["stretch_total"], st["Rm"])
        if accurate_enough(fast, st["stretch_total"], tol):
            return fast
        return membrane_energy(self.graph, self.edges.q, st["P"], st["R"])

    def _record(self, result, st, P_prev, tol, start, callback):
        P = st["P"]
        membrane = self._membrane(st, tol)
        bending = bending_energy(self.graph, st["R"], self._bending_alpha, self.area)
        total = membrane + bending
        if not np.isfinite(total):
            raise NumericalError(f"energy became non-finite at iteration {len(result.log)}")
        if P_prev is None:
            rel, move = float("nan"), 0.0
        else:
            previous = result.log[-1]["total"]
            rel = abs(total - previous) / max(abs(previous), self._energy_floor)
            d = P - P_prev
            move = float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d), initial=0.0)))
        row = {"iteration": len(result.log), "membrane": membrane, "bending": bending,
               "total": total, "rel_change": rel, "max_move": move,
               "seconds": time.perf_counter() - start}
        result.log.append(row)
        if callback is not None:
            callback(row)
        return row


def unanchored(graph, constrained):
    """Vertices nothing can move: unreferenced ones and every connected part without a
    constrained vertex. Returns their sorted ids and a warning per kind found.

    Parameters
    ----------
    graph : CellGraph
    constrained : (n,) bool array
    """
    n_parts, label = csgraph.connected_components(graph.laplacian, directed=False)
    anchored = np.zeros(n_parts, dtype=bool)
    anchored[label[constrained]] = True
    lonely = np.flatnonzero((graph.degree == 0) & ~constrained)
    floating = np.flatnonzero(~anchored[label] & (graph.degree > 0))
    notes = []
    if lonely.size:
        notes.append(f"{lonely.size} unreferenced vertices kept at rest")
    if floating.size:
        parts = np.unique(label[floating]).size
        notes.append(f"{parts} connected part(s) without a constrained vertex "
                     f"({floating.size} vertices) kept at rest")
    return np.union1d(lonely, floating), notes


def weight_warnings(graph):
    """Warnings about edge weights that can keep a solve from settling."""
    out = []
    if graph.degenerate:
        out.append(f"{graph.degenerate} triangle angles of zero-area faces have no finite "
                   "cotangent; their weights count as 0")
    negative = int(np.count_nonzero(graph.c < 0)) // 2
    if negative:
        out.append(f"{negative} edges have negative cotangent weights: the membrane energy is "
                   "not bounded below and the solve may not settle; use --weights "
                   "cotan-clamped (default) or uniform")
    return out


def deform(V, F, constrained, targets, **options):
    """One-shot deformation: build a :class:`Deformer` and solve once.

    Parameters
    ----------
    V : (n, 3) float array
    F : (f, 3) int array
    constrained : (k,) int array
    targets : (k, 3) float array
    **options : ``alpha``, ``feedback``, ``weights``, ``area`` go to the Deformer;
        ``max_iter``, ``tol``, ``initial``, ``callback`` to :meth:`Deformer.solve`

    Returns
    -------
    DeformResult
    """
    solve_keys = {"max_iter", "tol", "initial", "callback"}
    solve_opts = {k: v for k, v in options.items() if k in solve_keys}
    build_opts = {k: v for k, v in options.items() if k not in solve_keys}
    return Deformer(V, F, constrained, **build_opts).solve(targets, **solve_opts)
