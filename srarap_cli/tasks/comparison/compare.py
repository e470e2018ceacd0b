"""How far apart two meshes are: per vertex when they share topology, else by surfaces; and
the one place a distance becomes a fraction of the mesh's diagonal (:meth:`Comparison.scaled`)
and a verdict against a tolerance (:meth:`Comparison.verdict`), for ``compare``, a batch
job's golden check and its report."""
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...io.mesh.mesh import Mesh
from ...solver.libigl import igl


def same_topology(a: Mesh, b: Mesh) -> bool:
    """Same vertex count and the same polygons in the same order."""
    return (len(a.vertices) == len(b.vertices) and np.array_equal(a.face_sizes, b.face_sizes)
            and np.array_equal(a.face_vertices, b.face_vertices))


@dataclass(frozen=True)
class Verdict:
    """A :class:`Comparison` against a tolerance: ``within``, and ``beyond``, the fraction of
    the compared vertices farther than ``tol`` (in the comparison's unit)."""

    tol: float
    within: bool
    beyond: float


@dataclass(frozen=True)
class Comparison:
    """Distances between meshes A and B.

    Attributes
    ----------
    mode : {"per-vertex", "surface"}
    max, mean, rms : float, in the comparison's unit: model units, or fractions of A's
        bounding-box diagonal once :meth:`scaled` with ``relative``
    diagonal : float, of A's bounding box, in model units
    farthest : dict or None, the vertex farthest from the other mesh (``mesh``: "a" or "b",
        ``vertex``: its index, ``position``: where it is in that mesh)
    distances : (n,) float array, in model units: every vertex's distance (per vertex: of
        A's vertices; by surface: A's then B's)
    scale : float, what a model-unit distance is divided by (the diagonal, or 1)
    """

    mode: str
    max: float
    mean: float
    rms: float
    diagonal: float
    farthest: dict[str, Any] | None
    distances: np.ndarray
    scale: float = 1.0

    @property
    def relative(self) -> bool:
        return self.scale != 1.0

    def scaled(self, relative: bool) -> "Comparison":
        """This comparison's figures as fractions of the diagonal where ``relative`` (and the
        diagonal is not 0), else in model units."""
        s = self.diagonal if relative and self.diagonal > 0 else 1.0
        return replace(self, max=self.max * self.scale / s, mean=self.mean * self.scale / s,
                       rms=self.rms * self.scale / s, scale=s)

    def verdict(self, tol: float) -> Verdict:
        d = self.distances / self.scale
        return Verdict(tol, self.max <= tol, float(np.mean(d > tol)) if d.size else 0.0)

    def of_b(self, n_b: int) -> np.ndarray:
        """(n_b,) model-unit distances of B's vertices (a difference picture colours B)."""
        return self.distances if self.mode == "per-vertex" else self.distances[-n_b:]


def compare_meshes(a: Mesh, b: Mesh) -> Comparison:
    """Distances between meshes ``a`` and ``b`` (Mesh), in model units.

    Same topology: per-vertex distances ``|a_i - b_i|`` (max, mean, RMS). Otherwise: the
    symmetric Hausdorff distance of the two surfaces (libigl) as ``max``, and the mean and RMS
    of every vertex's distance to the other surface, both ways.

    Examples
    --------
    >>> a = Mesh.from_arrays(np.array([[0., 0, 0], [3, 0, 0], [0, 4, 0]]), np.array([[0, 1, 2]]))
    >>> c = compare_meshes(a, a.with_vertices(a.vertices + [0, 0, 0.5]))
    >>> c.mode, c.max, c.diagonal, c.scaled(True).max, c.verdict(1.0).within
    ('per-vertex', 0.5, 5.0, 0.1, True)
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
    return Comparison(mode, worst, float(d.mean()), float(np.sqrt(np.mean(d ** 2))), diagonal,
                      _farthest(d, a, b), d)


def _farthest(d, a, b):
    """Which vertex is farthest from the other mesh, and where it is."""
    if not d.size:
        return None
    k = int(np.argmax(d))
    mesh, V = ("a", a.vertices) if k < len(a.vertices) else ("b", b.vertices)
    k = k if mesh == "a" else k - len(a.vertices)
    return {"mesh": mesh, "vertex": k, "position": V[k].tolist()}
