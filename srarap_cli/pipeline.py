"""From a mesh and its constraints to the deformed mesh: the path every command shares."""
from dataclasses import dataclass

import numpy as np

from .deformer import Deformer, DeformResult
from .mesh_checks import mesh_warnings, solvable_faces
from .operators import mesh_area
from .quaternion import IDENTITY
from .region import restrict

DEFAULTS = {"alpha": 0.14, "feedback": 0.2, "max_iter": 1000, "tol": 1e-6,
            "weights": "cotan-clamped", "method": "sr-linear-sym", "sweeps": 2}


def settings(file_settings, overrides):
    """Defaults, then the handle file's ``solver`` section, then explicit options (not None)."""
    out = dict(DEFAULTS)
    out.update(file_settings)
    out.update({k: v for k, v in overrides.items() if v is not None})
    return out


@dataclass
class Problem:
    """The triangle mesh a solve works on (all of it, or the region of interest's part).

    Attributes
    ----------
    vertices : (s,) int array, ids in the full mesh
    V : (s, 3) float array; F : (f, 3) int array, in solve ids
    ids : (k,) int array, constrained solve ids; targets : (k, 3) float array
    area : float or None, the whole mesh's area when the solve covers only a region
    """

    vertices: np.ndarray
    V: np.ndarray
    F: np.ndarray
    ids: np.ndarray
    targets: np.ndarray
    area: float = None
    sub: object = None

    def targets_for(self, constraint_targets):
        """Solve targets for a new set of constraint targets (same constrained vertices)."""
        if self.sub is None:
            return constraint_targets
        out = self.targets.copy()
        out[self.sub.slots] = constraint_targets[self.sub.which]
        return out


def problem(mesh, constraints):
    """Triangulate ``mesh`` (faces that repeat a vertex left out) and cut it down to the
    region of interest, if there is one."""
    V = mesh.vertices
    F = solvable_faces(mesh.triangles()[0])
    if constraints.region is None:
        return Problem(np.arange(len(V)), V, F, constraints.ids, constraints.targets)
    sub = restrict(V, F, constraints.ids, constraints.targets, constraints.region)
    return Problem(sub.vertices, V[sub.vertices], sub.faces, sub.constrained, sub.targets,
                   mesh_area(V, F), sub)


def build_deformer(p, opts):
    """The :class:`Deformer` of a :class:`Problem` with resolved settings ``opts``."""
    return Deformer(p.V, p.F, p.ids, alpha=opts["alpha"], feedback=opts["feedback"],
                    weights=opts["weights"], area=p.area, method=opts["method"],
                    sweeps=opts["sweeps"])


def scatter(mesh, p, positions):
    """Full-mesh positions from a problem's solved positions."""
    out = mesh.vertices.copy()
    out[p.vertices] = positions
    return out


def deform_mesh(mesh, constraints, callback=None, **overrides):
    """Deform a :class:`~srarap_cli.mesh_io.Mesh` by its :class:`~srarap_cli.handles.Constraints`.

    Parameters
    ----------
    mesh : Mesh
    constraints : Constraints
    callback : callable(dict), optional, receives each log row
    **overrides : alpha, feedback, max_iter, tol, weights, method, sweeps

    Returns
    -------
    deformed : Mesh, same vertices and faces, new positions and normals
    result : DeformResult, positions/rotors of the whole mesh
    warnings : list of str
    """
    opts = settings(constraints.solver, overrides)
    p = problem(mesh, constraints)
    deformer = build_deformer(p, opts)
    sub_result = deformer.solve(p.targets, max_iter=opts["max_iter"], tol=opts["tol"],
                                callback=callback)
    positions = scatter(mesh, p, sub_result.positions)
    rotors = np.tile(IDENTITY, (len(positions), 1))
    rotors[p.vertices] = sub_result.rotors
    result = DeformResult(positions, rotors, sub_result.log, sub_result.converged,
                          sub_result.iterations)
    notes = mesh_warnings(mesh.vertices, mesh.triangles()[0]) + list(deformer.warnings)
    return mesh.with_vertices(positions), result, notes
