"""From a mesh and its constraints to the deformed mesh: the path every command shares."""
import numpy as np

from .deformer import Deformer, DeformResult
from .operators import mesh_area
from .quaternion import IDENTITY
from .region import restrict

DEFAULTS = {"alpha": 0.14, "feedback": 0.2, "max_iter": 1000, "tol": 1e-6, "weights": "cotan-clamped"}


def settings(file_settings, overrides):
    """Defaults, then the handle file's ``solver`` section, then explicit options (not None)."""
    out = dict(DEFAULTS)
    out.update(file_settings)
    out.update({k: v for k, v in overrides.items() if v is not None})
    return out


def deform_mesh(mesh, constraints, callback=None, **overrides):
    """Deform a :class:`~srarap_cli.mesh_io.Mesh` by its :class:`~srarap_cli.handles.Constraints`.

    Parameters
    ----------
    mesh : Mesh
    constraints : Constraints
    callback : callable(dict), optional, receives each log row
    **overrides : alpha, feedback, max_iter, tol, weights

    Returns
    -------
    deformed : Mesh, same vertices and faces, new positions and normals
    result : DeformResult, positions/rotors of the whole mesh
    warnings : list of str
    """
    opts = settings(constraints.solver, overrides)
    V = mesh.vertices
    F, _ = mesh.triangles()
    area_all = None
    if constraints.region is not None:
        sub = restrict(V, F, constraints.ids, constraints.targets, constraints.region)
        area_all = mesh_area(V, F)
        verts, faces, ids, targets = sub.vertices, sub.faces, sub.constrained, sub.targets
    else:
        verts, faces, ids, targets = np.arange(len(V)), F, constraints.ids, constraints.targets
    deformer = Deformer(V[verts], faces, ids, alpha=opts["alpha"], feedback=opts["feedback"],
                        weights=opts["weights"], area=area_all)
    sub_result = deformer.solve(targets, max_iter=opts["max_iter"], tol=opts["tol"],
                                callback=callback)
    positions = V.copy()
    positions[verts] = sub_result.positions
    rotors = np.tile(IDENTITY, (len(V), 1))
    rotors[verts] = sub_result.rotors
    result = DeformResult(positions, rotors, sub_result.log, sub_result.converged,
                          sub_result.iterations)
    return mesh.with_vertices(positions), result, list(deformer.warnings)
