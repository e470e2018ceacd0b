"""Deformer: precompute once per mesh and constraint set, then solve for any targets.

The solve is composed of parts that each live in their own module: a start
(:mod:`srarap_cli.solver.starts`) makes the first :class:`~srarap_cli.solver.state.State`, a driver
(:mod:`srarap_cli.solver.drivers`) repeats the local/global step (:mod:`srarap_cli.solver.step`) and decides
when to stop. This class holds what they share: weights, rest edges, the factored Poisson
matrix and the local step.
"""
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import csgraph

from ..runtime.parallel import numerics
from ..runtime.warning_codes import note
from . import api_checks
from .drivers import ACCEL_DRIVERS, DRIVERS, Monitor
from .energy import bending_energy, membrane_energy
from .global_step import PoissonSolver
from .group_rotations import connected_groups
from .linear_response import LinearResponse
from .local_step import METHODS
from .mesh_checks import geometry_problem
from .operators import cell_graph
from .rest_edges import RestEdges
from .result import DeformResult
from .settings import Settings, with_keywords
from .starts import STARTS, WARM_STARTS
from .step import LocalGlobalStep
from .stop import StopReason


class Deformer:
    """SR-ARAP deformation of one triangle mesh with one set of constrained vertices.

    Builds the edge weights, rest edges, the Poisson factorization and the local step once;
    :meth:`solve` then runs a start and a driver for any targets.

    Parameters
    ----------
    V : (n, 3) float array, rest positions
    F : (f, 3) int array, triangles
    constrained : (k,) int array, ids of vertices whose positions are prescribed
    settings : Settings, optional, every solver setting at once (default: the defaults);
        the solve settings in it are what :meth:`solve` uses unless told otherwise
    **options : setup and solve settings by name, over ``settings`` (the setup ones below;
        see :mod:`srarap_cli.solver.settings`)
    area : float, optional; ``A`` in the energy, default the surface area of (V, F)
    labels : (k,) int array, optional, handle group of each constrained vertex (the
        rotation-aware start fits one rotation per group); default: the connected patches
        the constrained vertices form
    prepare : bool, factor and build the local step now (False: on first use, for a
        multiresolution solver that may only need the fine mesh's energy)

    Other Parameters
    ----------------
    alpha : float > 0, bending weight (energy uses ``alpha * area``)
    feedback : float >= 0, pull of each rotor toward its previous value (paper's eps)
    weights : {"cotan-clamped", "cotan", "uniform"}
    method : {"sr-linear-sym", "sr-linear", "sr-relax", "arap"}
        Local step: the symmetric total-energy variant of the paper's one-solve system (the
        default: fastest to a given energy on the benchmarks), the paper's system itself,
        per-cell relaxation sweeps, or classic ARAP (no bending term).
    sweeps : int, relaxation sweeps per iteration for ``sr-relax``
    handle_rotors : {"boundary", "lagged"}
        Which constrained vertices' rotors ``sr-linear-sym`` and ``sr-linear`` take from
        their own 4x4 rows with the neighbours' previous rotors (the paper's section 6.2),
        as known values for the one sparse solve: those on a handle's boundary (a free
        neighbour), the interior of each handle joining the sparse solve (the default), or
        all of them (``lagged``). Lagged, a rotation reaches the middle of a handle one ring
        of cells per iteration: large handles, like the Max bust's 2371 of 5272 vertices,
        took the plain iteration 123 iterations to 0.1% of the minimum against 43 (Spot 896
        against 168, cylinder 338 against 85). The interior rotors then enter their
        neighbours' rows unnormalized instead of normalized, which moved the tightly
        converged shapes of the benchmark cases by at most 1e-5 of the bounding-box diagonal.
        With ``feedback = 0`` the rule is ``lagged`` (a handle without a boundary, a whole
        constrained part, would have no right-hand side).

    Attributes
    ----------
    settings : Settings, the resolved settings the solver was built with
    fixed : (j,) int array, every vertex whose position is held: constrained and auto_fixed
    constrained_slots : (k,) int array, where each constrained vertex sits in ``fixed``
    diagonal : float, the rest mesh's bounding-box diagonal (scale of the stopping test)
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

    def __init__(self, V: ArrayLike, F: ArrayLike, constrained: ArrayLike, *,
                 settings: Settings | None = None, area: float | None = None,
                 labels: ArrayLike | None = None, prepare: bool = True,
                 **options: Any) -> None:
        self.settings = with_keywords(settings, options, ("setup", "solve"), "Deformer")
        self._build(V, F, constrained, area, labels, prepare, threads=self.settings.threads)

    @numerics
    def _build(self, V, F, constrained, area, labels, prepare):
        s = self.settings
        self.V, self.F = api_checks.mesh_arrays(V, F)
        why = geometry_problem(self.V, self.F)
        if why is not None:
            raise ValueError(f"V, F: {why}")
        self.graph = cell_graph(self.V, self.F, s.weights)
        self.area = self.graph.area if area is None else api_checks.positive(area, "area")
        self.constrained = api_checks.vertex_ids(constrained, len(self.V))
        self._mask = np.zeros(len(self.V), dtype=bool)
        self._mask[self.constrained] = True
        self.warnings = weight_warnings(self.graph)
        self.auto_fixed, notes = unanchored(self.graph, self._mask)
        self.warnings += notes
        self._mask[self.auto_fixed] = True
        self.fixed = np.flatnonzero(self._mask)
        self.constrained_slots = np.searchsorted(self.fixed, self.constrained)
        self.labels = (connected_groups(self.graph.laplacian, self.constrained)
                       if labels is None else api_checks.labels(labels, len(self.constrained)))
        self.edges = RestEdges(self.graph, self.V)
        self.energy_scale = max(float(self.graph.c @ self.edges.q_sq), 1e-300)
        self.diagonal = float(np.linalg.norm(np.ptp(self.V, axis=0)))
        self._bending_alpha = s.alpha if METHODS[s.method].bending else 0.0
        self._poisson: PoissonSolver | None = None
        self._local_step: Any = None
        self._response: LinearResponse | None = None
        if prepare:
            self.prepare()

    def __repr__(self) -> str:
        s = self.settings
        return (f"Deformer({len(self.V)} vertices, {len(self.F)} triangles, "
                f"{len(self.constrained)} constrained; {s.method}, alpha {s.alpha:g}, "
                f"weights {s.weights})")

    def prepare(self) -> "Deformer":
        """Factor the Poisson matrix and build the local step, if not done yet."""
        if self._poisson is None:
            self._poisson = PoissonSolver(self.graph, self._mask)
            s = self.settings
            self._local_step = METHODS[s.method](self.edges, self._rotor_mask(),
                                                 s.alpha * self.area, s.feedback,
                                                 **s.method_options())
        return self

    def _rotor_mask(self):
        """Vertices whose rotors the local step takes from their own rows (see
        ``handle_rotors``), and every vertex nothing can move."""
        if self.settings.handle_rotors == "lagged" or not self.settings.feedback > 0:
            return self._mask
        g, held = self.graph, np.zeros_like(self._mask)
        held[g.I[self._mask[g.I] & ~self._mask[g.J]]] = True
        held[self.auto_fixed] = True
        return held

    @property
    def poisson(self) -> Any:
        """The factored Poisson matrix (global step)."""
        return self.prepare()._poisson

    @property
    def linear_response(self) -> LinearResponse:
        """The first-order change of a solved state under a move of the held vertices
        (warm starts); built on first use."""
        if self._response is None:
            self._response = LinearResponse(self.prepare())
        return self._response

    @property
    def bending_weight(self) -> float:
        """``alpha * A``, the bending term's factor (0 for classic ARAP)."""
        return self._bending_alpha * self.area

    @property
    def local_step(self) -> Any:
        """The method's local step (see :mod:`srarap_cli.solver.local_step`)."""
        return self.prepare()._local_step

    def fixed_targets(self, targets: np.ndarray) -> np.ndarray:
        """Positions (j, 3) of every held vertex (``fixed``): ``targets`` for the constrained
        ones, rest positions for the rest."""
        full = self.V[self.fixed].copy()
        full[self.constrained_slots] = targets
        return full

    def bending(self, R: np.ndarray) -> float:
        """The bending energy of rotors ``R`` (n, 4) (0 for classic ARAP)."""
        return bending_energy(self.graph, R, self._bending_alpha, self.area)

    def energy(self, P: np.ndarray, R: np.ndarray) -> dict[str, float]:
        """Energy terms of any positions ``P`` (n, 3) with rotors ``R`` (n, 4), from per-edge
        residuals (accurate near rigid motions): dict ``membrane``, ``bending``, ``total``."""
        membrane = membrane_energy(self.graph, self.edges.q, P, R)
        bending = self.bending(R)
        return {"membrane": membrane, "bending": bending, "total": membrane + bending}

    def best_rotors(self, P: np.ndarray, R_prev: np.ndarray) -> np.ndarray:
        """One local step: the rotors (n, 4) the method gives positions ``P`` (n, 3), with
        ``R_prev`` as the previous rotors (feedback, hemispheres)."""
        return self.local_step.step(self.edges.cross(P),
                                    self.edges.stretch(P) if self.local_step.needs_stretch
                                    else None, R_prev)

    def step_for(self, targets: np.ndarray, tol: float | None = None) -> "LocalGlobalStep":
        """The :class:`~srarap_cli.solver.step.LocalGlobalStep` of one set of targets
        (``tol``: default the solver's setting)."""
        return LocalGlobalStep(self, targets, self.settings.tol if tol is None else tol)

    def solve(self, targets: ArrayLike, *, initial: tuple[np.ndarray, np.ndarray] | None = None,
              callback: Callable[[dict], None] | None = None,
              settings: Settings | None = None, start: str | None = None,
              driver: Callable | str | None = None, **options: Any) -> DeformResult:
        """Deform toward ``targets`` for the constrained vertices.

        Parameters
        ----------
        targets : (k, 3) float array, in the order of ``constrained``
        initial : (positions (n, 3), rotors (n, 4)), optional warm start: an earlier
            solve's result (``warm``: the start follows the change of the targets to first
            order) or a state that already follows them (``extrapolated``)
        callback : callable(dict), called with each log row
        settings : Settings, optional; its solve settings replace the solver's own for this
            solve (its setup settings must be the solver's: ValueError otherwise)
        start : str, optional, a name in :data:`srarap_cli.solver.starts.STARTS`; overrides
            the ``start`` setting (``harmonic`` or ``laplacian``) with any registered start:
            with ``initial``, ``warm`` (any name but ``extrapolated``) or ``extrapolated``
            (see :mod:`srarap_cli.solver.starts.warm`)
        driver : str or callable, optional, a name in :data:`srarap_cli.solver.drivers.DRIVERS`
            or a driver itself; overrides ``accel``
        **options : solve settings by name, over ``settings``:
            ``max_iter`` (int >= 0, local/global iterations at most); ``tol`` (stop when the
            relative energy changes ``|E_k - E_{k-1}| / |E_{k-1}|`` of the last 3 steps
            average at most ``tol`` and the last step moved no vertex by more than
            ``sqrt(tol)`` of the diagonal of the box around the rest mesh and the targets;
            see :mod:`srarap_cli.solver.drivers.monitor`); ``time_limit`` (seconds, stop
            not converged); ``accel`` (``anderson`` or ``none``, the driver); ``start``
            (``harmonic`` or ``laplacian``, the first iterate without ``initial``);
            ``threads`` (int >= 1; default ``$SRARAP_THREADS``, else the CPUs this process
            may use: the same result at any count)

        Returns
        -------
        DeformResult
        """
        s = solve_settings(self.settings, settings, options, "solve")
        return self._solve(s, targets, initial, callback, start, driver, threads=s.threads)

    @numerics
    def _solve(self, s, targets, initial, callback, start, driver):
        targets = api_checks.targets(targets, len(self.constrained))
        if initial is not None:
            initial = api_checks.initial(initial, len(self.V))
        self.prepare()
        # the move test's scale spans the targets too: a handle sent a thousand diagonals
        # away moves vertices by more than the rest mesh's size in every converging step
        extent = np.ptp(np.vstack([self.V.min(axis=0), self.V.max(axis=0), targets]), axis=0)
        monitor = Monitor(max_iter=s.max_iter, tol=s.tol, time_limit=s.time_limit,
                          callback=callback, energy_scale=self.energy_scale,
                          scale=float(np.linalg.norm(extent)))
        step = self.step_for(targets, s.tol)
        start = start or s.start
        if start not in STARTS:
            raise ValueError(f"start must be one of {', '.join(STARTS)}, not {start!r}")
        if initial is not None and start not in WARM_STARTS:
            start = "warm"
        # a copy: a registered start may return a state it keeps
        first = replace(STARTS[start](step, initial), handed_over=True)
        run = driver if callable(driver) else DRIVERS.get(driver or ACCEL_DRIVERS[s.accel])
        if run is None:
            raise ValueError(f"driver {driver!r} is not one of {', '.join(map(repr, DRIVERS))} "
                             "or a callable")
        state = run(step, first, monitor)
        reason = monitor.reason or StopReason.DRIVER
        return DeformResult(state.positions, state.rotors, monitor.log, reason,
                            monitor.iterations, monitor.detail)


def solve_settings(own: Settings, given: Settings | None, options: dict[str, Any],
                   where: str) -> Settings:
    """The settings of one solve of a solver built with ``own``: ``given`` (a caller's
    Settings; its setup settings must equal ``own``'s) or ``own``, with the solve keywords
    ``options`` over them."""
    if given is not None:
        differ = own.fixed_at_setup(given)
        if differ:
            raise ValueError(f"{where}(): settings differ from the solver's in "
                             f"{', '.join(differ)}, fixed when it was built")
    return with_keywords(given or own, options, ("solve",), where)


def unanchored(graph: Any, constrained: np.ndarray) -> tuple[np.ndarray, list[str]]:
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
    placed = int(np.sum((graph.degree == 0) & constrained))
    notes: list[str] = []
    if lonely.size or placed:
        notes.append(note("unreferenced-vertices",
                          f"{lonely.size + placed} unreferenced vertices (in no triangle): "
                          f"{lonely.size} kept at rest, {placed} constrained ones placed at "
                          "their targets"))
    if floating.size:
        parts = np.unique(label[floating]).size
        notes.append(note("part-at-rest", f"{parts} connected part(s) without a constrained "
                          f"vertex ({floating.size} vertices) kept at rest"))
    return np.union1d(lonely, floating), notes


def weight_warnings(graph: Any) -> list[str]:
    """Warnings about edge weights that can keep a solve from settling."""
    out: list[str] = []
    if graph.degenerate:
        out.append(note("degenerate-angles", f"{graph.degenerate} triangle angles of zero-area "
                        "faces have no finite cotangent; their weights count as 0"))
    negative = int(np.count_nonzero(graph.c < 0)) // 2
    if negative:
        out.append(note("negative-weights", f"{negative} edges have negative cotangent weights: "
                        "the membrane energy is not bounded below and the solve may not "
                        "settle; use --weights cotan-clamped (default) or uniform"))
    return out
