"""From a mesh and its constraints to the deformed mesh: the path every command shares."""
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..io.handles import Constraints
from ..io.mesh import Mesh
from ..runtime.allocator import keep_freed_memory, one_arena
from ..runtime.errors import InputError
from ..runtime.stages import begun as stage_begun
from ..runtime.stages import ended as stage_ended
from ..runtime.warning_codes import failing
from ..solver.deformer import unanchored, weight_warnings
from ..solver.interface import Solver
from ..solver.mesh_checks import geometry_problem, mesh_warnings, solvable_faces
from ..solver.oneshot import make_deformer
from ..solver.operators import cell_graph, mesh_area
from ..solver.quaternion import IDENTITY
from ..solver.region import restrict
from ..solver.result import DeformResult
from ..solver.settings import STAGES, Settings, resolve, with_keywords
from .far_targets import refuse_far_targets
from .rigid_parts import rigid_part_warnings
from .still_requests import still_request_warnings


@dataclass
class Problem:
    """The triangle mesh a solve works on (all of it, or the region of interest's part).

    Attributes
    ----------
    vertices : (s,) int array, ids in the full mesh
    V : (s, 3) float array; F : (f, 3) int array, in solve ids
    ids : (k,) int array, constrained solve ids; targets : (k, 3) float array
    labels : (k,) int array, handle group of each constrained vertex (the file's first group
        holding it; vertices a region holds at rest form one more group)
    area : float or None, the whole mesh's area when the solve covers only a region
    """

    vertices: np.ndarray
    V: np.ndarray
    F: np.ndarray
    ids: np.ndarray
    targets: np.ndarray
    labels: np.ndarray
    area: float | None = None
    sub: Any = None

    def targets_for(self, constraint_targets: np.ndarray) -> np.ndarray:
        """Solve targets for a new set of constraint targets (same constrained vertices)."""
        if self.sub is None:
            return constraint_targets
        out = self.targets.copy()
        out[self.sub.slots] = constraint_targets[self.sub.which]
        return out


def problem(mesh: Mesh, constraints: Constraints, name: str = "mesh") -> Problem:
    """Triangulate ``mesh`` (faces that repeat a vertex left out) and cut it down to the
    region of interest, if there is one. ``name`` (the mesh's file) starts error messages.

    Raises
    ------
    InputError : no solvable geometry, or a region of interest with nothing free to move
    """
    V = mesh.vertices
    F = solvable_faces(mesh.triangles()[0])
    why = geometry_problem(V, F)
    if why is not None:
        raise InputError(f"{name}: {why}")
    if constraints.region is None:
        return Problem(np.arange(len(V)), V, F, constraints.ids, constraints.targets,
                       _labels(constraints, constraints.ids))
    sub = restrict(V, F, constraints.ids, constraints.targets, constraints.region)
    if not len(sub.faces):
        raise InputError(f"{name}: the region of interest holds no vertex free to move "
                         "(every vertex in it is constrained)")
    return Problem(sub.vertices, V[sub.vertices], sub.faces, sub.constrained, sub.targets,
                   _labels(constraints, sub.vertices[sub.constrained]), mesh_area(V, F), sub)


def _labels(constraints, full_ids):
    if not constraints.groups:  # (ids, targets) from the API: the solver finds the patches
        return None
    labels = np.full(len(full_ids), len(constraints.groups), dtype=np.int64)
    for g, members in reversed(list(enumerate(constraints.groups.values()))):
        labels[np.isin(full_ids, members)] = g
    return np.unique(labels, return_inverse=True)[1].ravel()


def command_solver(mesh: Mesh, p: Problem, opts: Settings, cache: str | None = None,
                   handle_warnings: Sequence[str] = (),
                   constraints: Constraints | None = None,
                   on_warnings: Callable[[list[str]], None] | None = None,
                   still: bool = True) -> tuple[Solver, list[str]]:
    """The solver of ``p`` for a command (deform, animate) and the warnings of the handle
    file (``handle_warnings``), the mesh, the solver and, given ``constraints``, the parts
    they carry off rigidly (:mod:`.rigid_parts`) or that ask for nothing to move (unless
    ``still`` is False, as for an animation, whose first frame is usually the rest pose:
    :func:`request_warnings`); under ``opts.strict`` the first
    warning is raised instead (before the solver is built, where it can be). The mesh checks
    run before the solver is built, so their temporaries (edge tables of the whole mesh) do
    not add to the memory it holds (2M-vertex bar: peak 11.4 -> 10.6 GiB); the process's
    threads share one allocator arena, and once the solver is built, the process keeps freed
    memory for reuse (:mod:`..runtime.allocator`). ``on_warnings`` hears the warnings as
    they are known, before the setup and before the solve (a log shows them before a long
    run, not after it)."""
    one_arena()  # before the checks and the setup start threads
    mark = time.perf_counter()
    stage_begun("checks")
    notes = list(handle_warnings) + mesh_warnings(mesh.vertices, mesh.triangles()[0])
    if constraints is not None:
        if still:  # a units slip costs seconds, not a solve of minutes
            refuse_far_targets(mesh.vertices, constraints, opts.allow, notes)
        notes += request_warnings(mesh, p, constraints, still)
    stage_ended("checks", time.perf_counter() - mark)
    if failing(notes, opts.strict, opts.allow):  # with what the setup would say: all at once
        refuse_warnings(opts, notes + model_warnings(p, opts))
    if on_warnings is not None:
        on_warnings(list(notes))
    mark = time.perf_counter()
    stage_begun("setup")
    deformer = make_deformer(p.V, p.F, p.ids, p.labels, settings=opts, area=p.area,
                             cache=cache)
    stage_ended("setup", time.perf_counter() - mark)
    keep_freed_memory()  # after the setup, whose large arrays are allocated once
    notes += list(deformer.warnings)
    refuse_warnings(opts, notes)
    if on_warnings is not None:
        on_warnings(list(deformer.warnings))
    return deformer, notes


def request_warnings(mesh: Mesh, p: Problem, constraints: Constraints,
                     still: bool = True) -> list[str]:
    """What the handles ask that deserves a word before a solve: nothing to deform (every
    vertex held, every handle at rest: :mod:`.still_requests`, unless ``still`` is False: an
    animation's first frame is usually its rest pose) or connected parts they carry off
    rigidly (:mod:`.rigid_parts`). ``srarap info`` says the same."""
    said = still_request_warnings(mesh.vertices, constraints) if still else []
    if said:
        return said
    return rigid_part_warnings(mesh.vertices, p.F if p.sub is None else
                               solvable_faces(mesh.triangles()[0]), constraints)


def model_warnings(p: Problem, opts: Settings) -> list[str]:
    """What the solver will say of the problem's mesh and held vertices (edge weights, parts
    nothing holds), without building it: the same functions its setup calls, for ``srarap
    info``'s dry run. (A multiresolution solve adds its simplification's notes.)"""
    graph = cell_graph(p.V, p.F, opts.weights)
    held = np.zeros(len(p.V), dtype=bool)
    held[p.ids] = True
    return weight_warnings(graph) + unanchored(graph, held)[1]


def refuse_warnings(opts: Settings, warnings: Sequence[str]) -> None:
    """Under ``strict``, the warnings it fails on (:func:`~srarap_cli.runtime.warning_codes.failing`:
    the request's, or all, less ``allow``'s codes) as an :class:`InputError` (exit 4), every
    one of them in its line, so that one run shows all there is to mend."""
    said = failing(warnings, opts.strict, opts.allow)
    if said:
        more = f" (and {len(said) - 1} more: {'; '.join(said[1:])})" if len(said) > 1 else ""
        what = "warnings" if opts.strict == "all" else "warnings about the request"
        raise InputError(f"{said[0]}{more} (strict: {what} are errors; --allow CODE "
                         "accepts one)")


def scatter(mesh: Mesh, p: Problem, positions: np.ndarray, constraints: Constraints,
            constraint_targets: np.ndarray | None = None) -> np.ndarray:
    """Full-mesh positions from a problem's solved positions. Constrained vertices go to their
    targets even where a region of interest left them out of the solve (handle vertices
    whose triangles touch no movable vertex)."""
    out = mesh.vertices.copy()
    out[p.vertices] = positions
    out[constraints.ids] = constraints.targets if constraint_targets is None else constraint_targets
    return out


def deform_mesh(mesh: Mesh, constraints: Constraints, settings: Settings | None = None,
                callback: Callable[[dict], None] | None = None, cache: str | None = None,
                name: str = "mesh", on_warnings: Callable[[list[str]], None] | None = None,
                **options: Any) -> tuple[Mesh, DeformResult, list[str]]:
    """Deform a :class:`~srarap_cli.io.mesh.Mesh` by its :class:`~srarap_cli.io.handles.Constraints`.

    Parameters
    ----------
    mesh : Mesh
    constraints : Constraints
    settings : Settings, optional, resolved (:func:`srarap_cli.solver.settings.resolve`:
        the defaults, the handle file's ``solver`` section, then the command line's); default
        the handle file's settings over the defaults
    callback : callable(dict), optional, receives each log row
    cache : str, optional, folder for multiresolution coarse meshes
    name : str, the mesh's file, for error messages
    on_warnings : callable(list of str), optional, hears the warnings known before the
        setup and before the solve, as they are known (all of them are returned too)
    **options : solver settings by name, over ``settings``

    Returns
    -------
    deformed : Mesh, same vertices and faces, new positions and normals
    result : DeformResult, positions/rotors of the whole mesh
    warnings : list of str
    """
    settings = with_keywords(settings or resolve(constraints.solver), options, STAGES,
                             "deform_mesh")
    p = problem(mesh, constraints, name)
    deformer, notes = command_solver(mesh, p, settings, cache, constraints.warnings,
                                     constraints, on_warnings)
    mark = time.perf_counter()
    stage_begun("solve")
    sub_result = deformer.solve(p.targets, callback=callback)
    stage_ended("solve", time.perf_counter() - mark)
    positions = scatter(mesh, p, sub_result.positions, constraints)
    rotors = np.tile(IDENTITY, (len(positions), 1))
    rotors[p.vertices] = sub_result.rotors
    result = replace(sub_result, positions=positions, rotors=rotors)
    return mesh.with_vertices(positions), result, notes
