"""Multiresolution SR-ARAP (paper section 7): solve on a coarse subset mesh, spread its
rotors harmonically over the full mesh, finish with one Poisson solve."""
import time

import numpy as np

from ..deformer import (
    Deformer,
    DeformResult,
    NumericalError,
    unanchored,
    weight_warnings,
)
from ..energy import bending_energy, membrane_energy
from ..operators import cell_graph, mesh_area
from ..quaternion import IDENTITY
from ..rest_edges import RestEdges
from .cache import coarse_mesh
from .dirichlet import DirichletSolver
from .transfer import group_rotors, handle_rotors, spread_rotors


class MultiresDeformer:
    """Same interface as :class:`~srarap_cli.deformer.Deformer`, solved through a coarse mesh.

    Precomputes once: the coarse mesh (simplified, or read from ``cache``), the coarse
    :class:`Deformer`, and one factorization of the fine Laplacian with Dirichlet rows at the
    coarse, constrained and immovable vertices, which serves both the rotor transfer and
    the final Poisson solve.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array
    constrained : (k,) int array
    labels : (k,) int array, handle group of each constrained vertex (default: one group)
    size : int, wanted coarse vertex count
    cache : str, optional folder for coarse meshes
    area : float, optional, ``A`` of the energy (default: area of the full mesh)
    **options : alpha, feedback, weights, method, sweeps, as for Deformer

    Attributes
    ----------
    coarse : CoarseMesh; coarse_deformer : Deformer; stages : dict of precompute seconds;
    cache_hit : bool; warnings : list of str

    Examples
    --------
    >>> import igl
    >>> from .simplify import _octahedron
    >>> V, F = igl.loop(*igl.loop(*_octahedron()))
    >>> d = MultiresDeformer(V, F, np.arange(6), size=30)
    >>> r = d.solve(V[:6] + 1.0)
    >>> bool(np.abs(r.positions - (V + 1.0)).max() < 1e-9)
    True
    """

    def __init__(self, V, F, constrained, labels=None, *, size, cache=None, area=None,
                 **options):
        start = time.perf_counter()
        self.V = np.asarray(V, dtype=float)
        self.F = np.asarray(F, dtype=np.int64)
        self.constrained = np.asarray(constrained, dtype=np.int64).ravel()
        k = self.constrained.size
        self.labels = np.zeros(k, np.int64) if labels is None else np.asarray(labels, np.int64)
        self.n_groups = int(self.labels.max(initial=-1)) + 1
        groups = [self.constrained[self.labels == g] for g in range(self.n_groups)]
        self.coarse, self.cache_hit, notes = coarse_mesh(self.V, self.F, size, groups, cache)
        self.stages = {"simplify": time.perf_counter() - start}
        self.area = mesh_area(self.V, self.F) if area is None else float(area)
        self._build_coarse(options)
        mark = time.perf_counter()
        fixed_notes = self._build_fine()
        self.stages["factor"] = time.perf_counter() - mark
        self.alpha = self.coarse_deformer.alpha
        self._bending_alpha = self.alpha if self.coarse_deformer.local_step.bending else 0.0
        self.warnings = (weight_warnings(self.graph) + fixed_notes + notes
                         + [f"multires: {w}" for w in self.coarse.warnings])

    @property
    def info(self):
        """``vertices`` (coarse count), ``of`` (full count), ``cache_hit``."""
        return {"vertices": int(self.coarse.vertices.size), "of": len(self.V),
                "cache_hit": self.cache_hit}

    def _build_coarse(self, options):
        start = time.perf_counter()
        cv = self.coarse.vertices
        slot = np.full(len(self.V), -1)
        slot[self.constrained] = np.arange(self.constrained.size)
        in_coarse = slot[cv] >= 0
        self._coarse_slots = slot[cv][in_coarse]
        self.coarse_deformer = Deformer(self.V[cv], self.coarse.faces, np.flatnonzero(in_coarse),
                                        area=self.area, **options)
        self.stages["coarse_precompute"] = time.perf_counter() - start

    def _build_fine(self):
        """Dirichlet set (coarse, constrained and immovable vertices) and its factorization."""
        self.graph = cell_graph(self.V, self.F, self.coarse_deformer.weights)
        known = np.zeros(len(self.V), dtype=bool)
        known[self.constrained] = True
        self.auto_fixed, notes = unanchored(self.graph, known)  # as the direct solve would
        known[self.auto_fixed] = True
        known[self.coarse.vertices] = True
        self._known = np.flatnonzero(known)
        self._row = np.full(len(self.V), -1)
        self._row[self._known] = np.arange(self._known.size)
        self.edges = RestEdges(self.graph, self.V)
        self.solver = DirichletSolver(self.graph.laplacian, self._known)
        return notes

    def solve(self, targets, *, max_iter=200, tol=1e-6, initial=None, callback=None,
              time_limit=None):
        """Deform toward ``targets``; see :meth:`Deformer.solve`. ``log`` holds the coarse
        iterations, ``full_energy`` the full mesh's energy, ``stages`` the seconds per stage."""
        start = time.perf_counter()
        targets = np.asarray(targets, dtype=float).reshape(-1, 3)
        cv = self.coarse.vertices
        warm = None if initial is None else (np.asarray(initial[0])[cv],
                                              np.asarray(initial[1])[cv])
        coarse = self.coarse_deformer.solve(targets[self._coarse_slots], max_iter=max_iter,
                                            tol=tol, initial=warm, callback=callback,
                                            time_limit=time_limit)
        stages = dict(self.stages, coarse_solve=time.perf_counter() - start)
        mark = time.perf_counter()
        R = spread_rotors(self.solver, self._known_rotors(targets, coarse.rotors))
        stages["transfer"] = time.perf_counter() - mark
        mark = time.perf_counter()
        P = self.solver.solve(self._known_positions(targets, coarse.positions),
                              self.edges.rotated_divergence(R))
        stages["fine_solve"] = time.perf_counter() - mark
        membrane = membrane_energy(self.graph, self.edges.q, P, R)
        bending = bending_energy(self.graph, R, self._bending_alpha, self.area)
        if not (np.isfinite(P).all() and np.isfinite(membrane + bending)):
            raise NumericalError("the full-resolution solve produced non-finite values")
        return DeformResult(P, R, coarse.log, coarse.converged, coarse.iterations,
                            full_energy={"membrane": membrane, "bending": bending,
                                         "total": membrane + bending}, stages=stages,
                            coarse=self.info)

    def _known_rotors(self, targets, coarse_rotors):
        out = np.tile(IDENTITY, (self._known.size, 1))
        rot, determined = group_rotors(self.V[self.constrained], targets, self.labels,
                                       self.n_groups)
        out[self._row[self.constrained]] = handle_rotors(
            rot, determined, self.labels, self.n_groups, self._coarse_slots,
            coarse_rotors[self.coarse_deformer.constrained])
        out[self._row[self.coarse.vertices]] = coarse_rotors
        out[self._row[self.auto_fixed]] = IDENTITY
        return out

    def _known_positions(self, targets, coarse_positions):
        out = self.V[self._known].copy()
        out[self._row[self.coarse.vertices]] = coarse_positions
        out[self._row[self.constrained]] = targets
        return out
