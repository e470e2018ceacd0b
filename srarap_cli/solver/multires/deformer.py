"""Multiresolution SR-ARAP (paper section 7): solve on a coarse subset mesh, then either carry
the result to the full mesh the paper's way (rotors spread harmonically, one Poisson solve) or
start full-resolution iterations from it (coarse-to-fine)."""
import contextlib
import time
from collections.abc import Callable
from concurrent.futures import Future
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...runtime import memory
from ...runtime.errors import NumericalError
from ...runtime.parallel import numerics
from ...runtime.stages import begun as stage_begun
from ...runtime.stages import deeper
from ...runtime.stages import ended as stage_ended
from ...runtime.threads import background
from ...runtime.warning_codes import note, reworded
from .. import api_checks
from ..deformer import Deformer, solve_settings
from ..drivers import corrected_driver
from ..group_rotations import connected_groups, group_rotors
from ..mesh_checks import distinct_ids, edge_adjacency
from ..quaternion import IDENTITY
from ..result import STAGE_NAMES, DeformResult, MultiresPart
from ..settings import Settings, with_keywords
from ..starts import STARTS
from ..stop import StopReason
from .cache import coarse_mesh
from .correction import CoarseCorrection
from .dirichlet import DirichletSolver
from .prolong import nearest_coarse, prolong
from .size import coarse_size
from .transfer import orient_group_rotors, spread_rotors

#: full-resolution iterations of a warm solve before the coarse-grid corrections join
WARM_UNCORRECTED = 5
#: a coarse mesh keeping more than this fraction of the vertices gains nothing over a
#: full-resolution solve
NO_GAIN = 0.5


class _Delayed:
    """A coarse-grid correction that is never due in the first ``after`` iterations, built
    on first use (``make()``), so a solve that stops before needs no coarse step at all."""

    def __init__(self, make: Callable[[], CoarseCorrection], after: int) -> None:
        self.make, self.after = make, after
        self.correction: CoarseCorrection | None = None

    def due(self, iteration: int) -> bool:
        if iteration <= self.after:
            return False
        self.correction = self.correction or self.make()
        return self.correction.due(iteration)

    def __call__(self, state: Any, residual: np.ndarray) -> np.ndarray | None:
        assert self.correction is not None  # due() came first
        return self.correction(state, residual)


def _begun(key):
    """A stage begins (a heartbeat names it), under the summary's name for it."""
    stage_begun(f"multires: {STAGE_NAMES[key]}")


def _ended(key, seconds):
    """A stage's ``seconds``, said (``-v``) under the summary's name for it."""
    return stage_ended(f"multires: {STAGE_NAMES[key]}", seconds)


def _on_level(callback, level):
    """``callback`` given each row with its ``level`` too (a progress line says which mesh
    the iterations are on: they start again from 0 at full resolution)."""
    if callback is None:
        return None
    return lambda row: callback({**row, "level": level})


def _all_iterations(result):
    """Every iteration ``result`` ran, on every level."""
    return result.iterations + result.coarse_iterations


class MultiresDeformer:
    """Same interface as :class:`~srarap_cli.solver.deformer.Deformer`, solved through a coarse mesh.

    Precomputes once: the coarse mesh (simplified, or read from ``cache``), the coarse
    :class:`Deformer` and the fine :class:`Deformer` (weights, rest edges, immovable vertices
    and the energy of the full mesh). In ``transfer`` mode, one factorization of the fine
    Laplacian with Dirichlet rows at the coarse, constrained and immovable vertices serves
    both the rotor transfer and the final Poisson solve, and the fine Deformer factors
    nothing. In ``refine`` mode the fine Deformer is prepared to iterate, and each vertex's
    nearest coarse vertex is found once: the full-resolution iterations start from the coarse
    solution moved rigidly with those vertices (:mod:`.prolong`), much closer to the minimum
    than the paper's transfer, and the coarse mesh corrects their smooth error as they go
    (:mod:`.correction`). A refine-mode coarse mesh of ``AUTO_THRESHOLD`` vertices or more
    is itself solved by a MultiresDeformer, through a coarser mesh.

    The full-resolution setup runs in a background thread, beside the simplification and,
    in refine mode, on beside the coarse level's setup and the first solve's coarse
    iterations, which need none of it: the constructor returns once the fine Deformer is
    built, and the first solve waits for its factorizations only when its full-resolution
    stage begins (an error there is raised by that solve; a setup or solve that fails first
    waits for the background work, so that nothing of it runs on). The answers are the same
    bit for bit: the two threads share no data.

    Parameters
    ----------
    V : (n, 3) float array; F : (f, 3) int array
    constrained : (k,) int array
    labels : (k,) int array, handle group of each constrained vertex (default: the connected
        patches they form, as :class:`Deformer`)
    settings : Settings, optional, every solver setting (default: the defaults); its
        ``multires_mode`` says what follows the coarse solve: full-resolution iterations to
        ``tol`` started from it (``refine``), or the paper's transfer and nothing else
        (``transfer``, approximate)
    size : int, optional, wanted coarse vertex count (default: from the ``multires``
        setting; see :func:`.size.coarse_size`)
    cache : str, optional folder for coarse meshes
    area : float, optional, ``A`` of the energy (default: area of the full mesh)
    **options : any solver setting by name, over ``settings``

    Attributes
    ----------
    coarse : CoarseMesh; coarse_deformer : Deformer or MultiresDeformer; fine : Deformer
    (reading it waits for the full-resolution setup); stages : dict of precompute seconds
    (``factor`` once the full-resolution setup has ended); cache_hit : bool; warnings : list of str

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

    def __init__(self, V: ArrayLike, F: ArrayLike, constrained: ArrayLike,
                 labels: ArrayLike | None = None, *, settings: Settings | None = None,
                 size: int | None = None, cache: str | None = None, area: float | None = None,
                 **options: Any) -> None:
        self.settings = with_keywords(settings, options, ("setup", "solve", "build"),
                                      "MultiresDeformer")
        self._setup(V, F, constrained, labels, size, cache, area, threads=self.settings.threads)

    @numerics
    def _setup(self, V, F, constrained, labels, size, cache, area):
        self.mode = self.settings.multires_mode
        start, peak = time.perf_counter(), memory.start()
        _begun("simplify")
        self.V, self.F = api_checks.mesh_arrays(V, F)
        self.constrained = api_checks.vertex_ids(constrained, len(self.V))
        size = coarse_size(self.settings.multires, len(self.V)) if size is None else size
        if size is None:
            raise ValueError(f"multires {self.settings.multires} gives no coarse level for "
                             f"{len(self.V)} vertices")
        self.labels = (connected_groups(edge_adjacency(self.F, len(self.V)), self.constrained)
                       if labels is None else np.asarray(labels, np.int64))
        self.n_groups = int(self.labels.max(initial=-1)) + 1
        groups = [self.constrained[self.labels == g] for g in range(self.n_groups)]
        # the full-resolution setup needs no coarse mesh: it runs beside the simplification
        # (738k Spot: 50 s one after the other, 35 s side by side on two cores), and its
        # factorizations on beside the coarse setup and the first coarse solve (see _ready)
        built: Future[Deformer] = Future()
        self._prepared: Callable[[], float] | None = background(
            partial(self._fine_setup, area, built))
        try:
            self._build_levels(size, groups, cache, built, start)
        except Exception:
            self._settle()
            raise
        self.memory = {"setup": memory.stop(peak)}


    def __repr__(self) -> str:
        s = self.settings
        return (f"MultiresDeformer({len(self.V)} vertices through {self.coarse.vertices.size}, "
                f"{len(self.F)} triangles, {len(self.constrained)} constrained; {s.method}, "
                f"alpha {s.alpha:g}, {s.multires_mode})")

    def _build_levels(self, size, groups, cache, built, start):
        """Everything of the setup but the full-resolution factorizations (see __init__)."""
        self.coarse, self.cache_hit, notes = coarse_mesh(self.V, self.F, size, groups, cache)
        self.stages = {"simplify": _ended("simplify", time.perf_counter() - start)}
        self._fine, self._own_setup = built.result(), 0.0
        self.area = self._fine.area
        self.direct = self._no_gain()
        if self.direct is not None:
            return
        self._build_coarse(cache)
        mark = time.perf_counter()
        if self.mode == "refine":
            self._nearest = nearest_coarse(self._fine.edges, self.coarse.vertices)
        else:
            self._build_transfer()
        self._own_setup = time.perf_counter() - mark
        if self.mode != "refine":  # nothing left to factor beside the solve
            self._ready()
        self.warnings = (self._fine.warnings + notes
                         + [reworded(w, "multires: ") for w in self.coarse.warnings])

    @property
    def fine(self) -> Deformer:
        """The full-resolution :class:`Deformer`, prepared (refine mode)."""
        self._ready()
        return self._fine

    def _ready(self):
        """Wait for the full-resolution setup; its seconds go to the ``factor`` stage. In
        refine mode the first solve calls this only after its coarse solve, which then runs
        beside the full-resolution factorizations (1.2M-vertex cylinder: the main thread
        waited 6 s for them after the simplification, then set up and solved the coarse
        level for 11 s)."""
        if self._prepared is not None:
            seconds, self._prepared = self._prepared(), None
            self.stages["factor"] = _ended("factor", seconds + self._own_setup)

    def _settle(self):
        """After an error: wait for the full-resolution setup, its own outcome dropped, so
        that nothing of a failed call runs on (a batch worker's next job would share its
        core with it)."""
        wait, self._prepared = self._prepared, None
        if wait is not None:
            with contextlib.suppress(Exception):
                wait()

    def _no_gain(self):
        """The full-resolution Deformer when the simplification kept more than half the
        vertices (a triangle soup, a mesh of tiny parts): a coarse level would cost about
        as much as the mesh itself. None otherwise."""
        kept, used = self.coarse.vertices.size, distinct_ids(self.F, len(self.V)).size
        if kept <= NO_GAIN * used:
            return None
        self.fine.warnings.append(note("multires-no-gain", f"multires: the mesh simplifies only "
                                       f"to {kept} of its {used} vertices; solved at full "
                                       "resolution"))
        return self.fine

    @classmethod
    def or_direct(cls, *args: Any, **kwargs: Any) -> "MultiresDeformer | Deformer":
        """A MultiresDeformer, or the plain Deformer it found to be no slower."""
        built = cls(*args, **kwargs)
        return built if built.direct is None else built.direct

    def _fine_setup(self, area, built):
        """Build the full-resolution Deformer, hand it to ``built`` (a Future), then factor
        it (refine mode); returns the seconds of both."""
        mark = time.perf_counter()
        _begun("factor")
        try:
            fine = Deformer(self.V, self.F, self.constrained, settings=self.settings, area=area,
                            labels=self.labels, prepare=False)
        except BaseException as exc:
            built.set_exception(exc)
            raise
        built.set_result(fine)
        if self.mode == "refine":
            fine.prepare()
        return time.perf_counter() - mark

    def _part(self, **fields: Any) -> MultiresPart:
        return MultiresPart(int(self.coarse.vertices.size), self.cache_hit, **fields)

    def _build_coarse(self, cache):
        start = time.perf_counter()
        _begun("coarse_precompute")
        cv = self.coarse.vertices
        slot = np.full(len(self.V), -1)
        slot[self.constrained] = np.arange(self.constrained.size)
        in_coarse = slot[cv] >= 0
        self._coarse_slots = slot[cv][in_coarse]
        args = (self.V[cv], self.coarse.faces, np.flatnonzero(in_coarse))
        labels = self.labels[self._coarse_slots]
        size = coarse_size("auto", cv.size) if self.mode == "refine" else None
        self.coarse_deformer: Deformer | MultiresDeformer
        if size is None:
            self.coarse_deformer = Deformer(*args, settings=self.settings, area=self.area,
                                            labels=labels)
        else:  # a level between: coarse-to-fine and corrections from a coarser mesh again
            with deeper():  # its stages are the coarse level's
                self.coarse_deformer = MultiresDeformer.or_direct(
                    *args, labels, settings=self.settings, size=size, cache=cache,
                    area=self.area)
        self.stages["coarse_precompute"] = _ended("coarse_precompute",
                                                  time.perf_counter() - start)

    def _build_transfer(self):
        """Dirichlet set (coarse, held and immovable vertices) and its factorization."""
        known = np.zeros(len(self.V), dtype=bool)
        known[self._fine.fixed] = True
        known[self.coarse.vertices] = True
        self._known = np.flatnonzero(known)
        self._row = np.full(len(self.V), -1)
        self._row[self._known] = np.arange(self._known.size)
        self.solver = DirichletSolver(self._fine.graph.laplacian, self._known)

    def solve(self, targets: ArrayLike, *, initial: tuple[np.ndarray, np.ndarray] | None = None,
              callback: Callable[[dict], None] | None = None,
              settings: Settings | None = None, start: str | None = None,
              **options: Any) -> DeformResult:
        """Deform toward ``targets``; see :meth:`Deformer.solve` (``max_iter`` and
        ``time_limit`` hold for each level). Returns a
        :class:`~srarap_cli.solver.result.DeformResult` with its ``multires`` part."""
        begin = time.perf_counter()
        s = solve_settings(self.settings, settings, options, "solve")
        return self._solve(s, targets, initial, callback, start, begin, threads=s.threads)

    @numerics
    def _solve(self, s, targets, initial, callback, start, begin):
        targets = api_checks.targets(targets, len(self.constrained))
        if initial is not None:
            initial = api_checks.initial(initial, len(self.V))
        if initial is not None and self.mode == "refine":
            return self._warm(targets, initial, callback, s, start, begin)
        cv = self.coarse.vertices
        warm = None if initial is None else (np.asarray(initial[0])[cv],
                                              np.asarray(initial[1])[cv])
        peak = memory.start()
        _begun("coarse_solve")
        try:
            with deeper():
                coarse = self.coarse_deformer.solve(targets[self._coarse_slots], initial=warm,
                                                    callback=_on_level(callback, "coarse mesh"),
                                                    settings=s, start=start)
        except Exception:
            self._settle()
            raise
        coarse_seconds = time.perf_counter() - begin
        self._ready()
        stages = dict(self.stages, coarse_solve=_ended("coarse_solve", coarse_seconds))
        peaks = dict(self.memory, coarse_solve=memory.stop(peak))
        log = [dict(row, step="coarse-" + row["step"]) for row in coarse.log]
        if self.mode == "transfer":
            return self._transfer(targets, coarse, log, stages, begin, peaks)
        mark, peak = time.perf_counter(), memory.start()
        _begun("fine_start")
        first = self._fine_start(targets, s.tol, coarse, start or s.start)
        stages["fine_start"] = _ended("fine_start", time.perf_counter() - mark)
        peaks["fine_start"] = memory.stop(peak)
        mark, peak = time.perf_counter(), memory.start()
        _begun("fine_iterations")
        fine = self.fine.solve(targets, initial=first, start="extrapolated", callback=callback,
                               driver=self._driver(targets, s.tol, s.accel), settings=s)
        stages["fine_iterations"] = _ended("fine_iterations", time.perf_counter() - mark)
        peaks["fine_iterations"] = memory.stop(peak)
        offset, elapsed = len(log), mark - begin
        log += [dict(row, iteration=row["iteration"] + offset, seconds=row["seconds"] + elapsed)
                for row in fine.log]
        part = self._part(iterations=_all_iterations(coarse), stop_reason=coarse.stop_reason,
                          full_energy=fine.energies(), stages=stages, memory=peaks,
                          wall=time.perf_counter() - begin)
        return DeformResult(fine.positions, fine.rotors, log, fine.stop_reason, fine.iterations,
                            fine.stop_detail, multires=part)

    def _warm(self, targets, initial, callback, settings, start, begin):
        """A warm start (an animation's next frame, a nearby pose) goes straight to the
        full-resolution iterations: a coarse solve first would start them farther off than
        the caller's state (50k-vertex tube twisted 3 degrees a frame: 0.63 frames/s with a
        coarse solve per frame, 1.34 with none; the frames within 3e-5 of the diagonal of a
        direct solve's). The coarse-grid corrections join only after
        :data:`WARM_UNCORRECTED` iterations: a frame close to the last one converges in a
        few without them, and there each correction cost more than it saved (the same tube:
        1.5 frames/s corrected from the first iteration, 2.0 after 5, 2.4 never); a larger
        change leaves smooth error that needs them (184k Spot, targets scaled by 1.01: 43
        iterations, 16.6 s never corrected, 13 and 11.1 s from the first, 17 and 12.9 s after
        5)."""
        driver = corrected_driver(settings.accel, _Delayed(
            partial(self.coarse_correction, targets, settings.tol), WARM_UNCORRECTED))
        fine = self.fine.solve(targets, initial=initial, callback=callback, settings=settings,
                               start=start, driver=driver)
        stages = {"fine_iterations": time.perf_counter() - begin}
        part = self._part(full_energy=fine.energies(), stages=stages,
                          wall=time.perf_counter() - begin)
        return DeformResult(fine.positions, fine.rotors, list(fine.log), fine.stop_reason,
                            fine.iterations, fine.stop_detail, multires=part)

    def coarse_correction(self, targets: np.ndarray, tol: float | None = None) -> Any:
        """The :class:`~.correction.CoarseCorrection` of the full-resolution iterates for
        ``targets`` (k, 3) (refine mode; ``tol``: default the solver's setting)."""
        tol = self.settings.tol if tol is None else tol
        level, coarse_targets = self.coarse_deformer, targets[self._coarse_slots]
        inner = None
        if isinstance(level, MultiresDeformer):
            inner = level.coarse_correction(coarse_targets, tol)
            level = level.fine
        return CoarseCorrection(level.step_for(coarse_targets, tol), self.coarse.vertices,
                                self._nearest, inner)

    def _driver(self, targets, tol, accel):
        """The full-resolution driver with coarse-grid corrections where the driver takes
        them (the accelerated one); one that does not (the plain iteration) runs as it is."""
        return corrected_driver(accel, self.coarse_correction(targets, tol))

    def _fine_start(self, targets, tol, coarse, start):
        """The lower-energy of two full-resolution starts: one local/global step from the
        coarse result moved rigidly with each vertex's nearest coarse vertex, and the
        solver's own start (``start``; a caller's ``initial`` goes to :meth:`_warm`). The
        coarse solution is the better start where the deformation needs rotations the
        handles do not give (the Max bust's translated handles: 2% above the minimum against
        21%); the harmonic start where the handles give them all (exact for a rigid motion),
        or where the simplification lost what matters. One step's energy is an imperfect
        judge: on a twisted 100k bar the coarse start won it and then converged more slowly.

        Returns (positions (n, 3), rotors (n, 4)): not the whole state, whose covariances
        would stay alive through the full-resolution solve (0.05 GB at 738k vertices)."""
        step = self.fine.step_for(targets, tol)
        prolonged = prolong(self.V, self._nearest, self.coarse.vertices, coarse.positions,
                            coarse.rotors)
        candidates = [step(STARTS["extrapolated"](step, prolonged)), STARTS[start](step, None)]
        best = min(candidates, key=lambda state: state.total)
        return best.positions, best.rotors

    def _transfer(self, targets, coarse, log, stages, begin, peaks):
        """The paper's result: coarse rotors spread harmonically, one Poisson solve."""
        mark, peak = time.perf_counter(), memory.start()
        R = spread_rotors(self.solver, self._known_rotors(targets, coarse.rotors))
        stages["transfer"] = _ended("transfer", time.perf_counter() - mark)
        mark = time.perf_counter()
        P = self.solver.solve(self.known_positions(targets, coarse.positions),
                              self.fine.edges.rotated_divergence(R))
        stages["fine_solve"] = _ended("fine_solve", time.perf_counter() - mark)
        energy = self.fine.energy(P, R)
        if not (np.isfinite(P).all() and np.isfinite(energy["total"])):
            raise NumericalError("the full-resolution solve produced non-finite values")
        rest = self.V.copy()
        rest[self.constrained] = targets
        start = self.fine.energy(rest, np.tile(IDENTITY, (len(self.V), 1)))
        part = self._part(iterations=_all_iterations(coarse), stop_reason=coarse.stop_reason,
                          transfer=True, full_energy=energy, start_energy=start, stages=stages,
                          memory=dict(peaks, transfer=memory.stop(peak)),
                          wall=time.perf_counter() - begin)
        return DeformResult(P, R, log, StopReason.TRANSFER, 0, multires=part)

    def _known_rotors(self, targets, coarse_rotors):
        out = np.tile(IDENTITY, (self._known.size, 1))
        rot, determined = group_rotors(self.V[self.constrained], targets, self.labels,
                                       self.n_groups)
        out[self._row[self.constrained]] = orient_group_rotors(
            rot, determined, self.labels, self.n_groups, self._coarse_slots,
            coarse_rotors[self.coarse_deformer.constrained])
        out[self._row[self.coarse.vertices]] = coarse_rotors
        out[self._row[self.fine.auto_fixed]] = IDENTITY
        return out

    def known_positions(self, targets: np.ndarray, coarse_positions: np.ndarray) -> np.ndarray:
        """Positions (j, 3) of the transfer's Dirichlet vertices: targets for the
        constrained ones, the coarse solve's for coarse vertices, rest for the others."""
        out = self.V[self._known].copy()
        out[self._row[self.coarse.vertices]] = coarse_positions
        out[self._row[self.constrained]] = targets
        return out
