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
    bounding box); ``where``: the vertex farthest from the other mesh (``mesh``: "a" or
    "b", ``vertex``: its index, ``position``: where it is in that mesh); ``distances``:
    (n,) float array, every vertex's distance (per vertex: of ``a``'s vertices; by
    surface: ``a``'s then ``b``'s)
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
            "rms": float(np.sqrt(np.mean(d ** 2))), "diagonal": diagonal,
            "where": _farthest(d, a, b), "distances": d}


def _farthest(d, a, b):
    """Which vertex is farthest from the other mesh, and where it is."""
    if not d.size:
        return None
    k = int(np.argmax(d))
    mesh, V = ("a", a.vertices) if k < len(a.vertices) else ("b", b.vertices)
    k = k if mesh == "a" else k - len(a.vertices)
    return {"mesh": mesh, "vertex": k, "position": V[k].tolist()}


def beyond(figures: dict[str, Any], tol: float, relative: bool) -> float:
    """The fraction of the compared vertices farther than ``tol`` (a fraction of ``a``'s
    diagonal when ``relative``) from the other mesh."""
    d = figures["distances"]
    scale = figures["diagonal"] if relative and figures["diagonal"] > 0 else 1.0
    return float(np.mean(d / scale > tol)) if d.size else 0.0
