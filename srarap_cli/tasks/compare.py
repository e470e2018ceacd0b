"""How far apart two meshes are: per vertex when they share topology, else by surfaces."""

from typing import Any

import numpy as np

from ..io.mesh.mesh import Mesh
from ..solver.libigl import igl


def same_topology(a: Mesh, b: Mesh) -> bool:
    """Same vertex count and the same polygons in the same order."""
    return (len(a.vertices) == len(b.vertices) and np.array_equal(a.face_sizes, b.face_sizes)
            and np.array_equal(a.face_vertices, b.face_vertices))


def compare_meshes(a: Mesh, b: Mesh) -> dict[str, Any]:
    """Distances between meshes ``a`` and ``b`` (Mesh), in model units.

    Same topology: per-vertex distances ``|a_i - b_i|`` (max, mean, RMS). Otherwise: the
    symmetric Hausdorff distance of the two surfaces (libigl) as ``max``, and the mean and RMS
    of every vertex's distance to the other surface, both ways.

    Returns
    -------
    dict with keys mode ("per-vertex" or "surface"), max, mean, rms, diagonal (of ``a``'s
    bounding box)
    """
    diagonal = float(np.linalg.norm(np.ptp(a.vertices, axis=0)))
    if same_topology(a, b):
        d = np.linalg.norm(a.vertices - b.vertices, axis=1)
        mode, worst = "per-vertex", float(d.max(initial=0.0))
    else:
        Fa, Fb = a.triangles()[0], b.triangles()[0]
        d = np.sqrt(np.concatenate([
            igl.point_mesh_squared_distance(a.vertices, b.vertices, Fb)[0],
            igl.point_mesh_squared_distance(b.vertices, a.vertices, Fa)[0]]))
        mode, worst = "surface", float(igl.hausdorff(a.vertices, Fa, b.vertices, Fb))
    return {"mode": mode, "max": worst, "mean": float(d.mean()),
            "rms": float(np.sqrt(np.mean(d ** 2))), "diagonal": diagonal}
