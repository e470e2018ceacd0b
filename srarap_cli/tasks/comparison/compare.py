"""How far apart two meshes are: per vertex when they share topology, else by surfaces (both
one-sided distances); optionally after the best rigid motion of B onto A; and the one place a
distance becomes a fraction of the mesh's diagonal (:meth:`Comparison.scaled`) and a verdict
against a tolerance (:meth:`Comparison.verdict`), for ``compare``, a batch job's golden check,
the pytest fixture and their reports."""
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ...io.mesh.mesh import Mesh
from ...runtime.errors import UsageProblem
from ...solver.libigl import igl
from .align import moved, rigid_motion

#: how the distances of two meshes that do not share vertices are sampled (said in the JSON)
SURFACE_SAMPLING = "every vertex of one mesh, to the closest point of the other's surface"
#: the alignments ``compare --align`` and ``expect: {align: ...}`` take
ALIGNMENTS = ("none", "rigid")


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
    max, mean, rms, p95, p99 : float, in the comparison's unit: model units, or fractions of
        A's bounding-box diagonal once :meth:`scaled` with ``relative``
    diagonal : float, of A's bounding box, in model units
    farthest : dict or None, the vertex farthest from the other mesh (``mesh``: "a" or "b",
        ``vertex``: its index, ``position``: where it is in that mesh)
    distances : (n,) float array, in model units: every vertex's distance (per vertex: of
        A's vertices; by surface: A's then B's)
    scale : float, what a model-unit distance is divided by (the diagonal, or 1)
    one_sided : dict or None, by surface only: ``a_to_b`` and ``b_to_a``, each ``max``,
        ``mean``, ``rms``, ``p95``, ``p99`` (the comparison's unit) and ``samples`` (how many
        points were measured), and ``sampling`` (how they were chosen)
    motion : dict or None, with ``align="rigid"``: the rigid motion applied to B before
        measuring (``rotation`` (3, 3), ``translation`` (3,) in model units, ``angle``
        in degrees, ``axis``)
    """

    mode: str
    max: float
    mean: float
    rms: float
    diagonal: float
    farthest: dict[str, Any] | None
    distances: np.ndarray
    scale: float = 1.0
    p95: float = 0.0
    p99: float = 0.0
    one_sided: dict[str, Any] | None = None
    motion: dict[str, Any] | None = None

    @property
    def relative(self) -> bool:
        return self.scale != 1.0

    def scaled(self, relative: bool) -> "Comparison":
        """This comparison's figures as fractions of the diagonal where ``relative`` (and the
        diagonal is not 0), else in model units."""
        s = self.diagonal if relative and self.diagonal > 0 else 1.0
        k = self.scale / s
        sides = None if self.one_sided is None else {
            name: ({q: (v * k if q in _FIGURES else v) for q, v in side.items()}
                   if isinstance(side, dict) else side)
            for name, side in self.one_sided.items()}
        return replace(self, max=self.max * k, mean=self.mean * k, rms=self.rms * k,
                       p95=self.p95 * k, p99=self.p99 * k, one_sided=sides, scale=s)

    def verdict(self, tol: float) -> Verdict:
        d = self.distances / self.scale
        return Verdict(tol, self.max <= tol, float(np.mean(d > tol)) if d.size else 0.0)

    def of_b(self, n_b: int) -> np.ndarray:
        """(n_b,) model-unit distances of B's vertices (a difference picture colours B)."""
        return self.distances if self.mode == "per-vertex" else self.distances[-n_b:]

    def row_figures(self, tol: float) -> dict[str, Any]:
        """The figures a job's result row keeps (:class:`~..job_status.JobResult`'s
        ``compare_*``, ``beyond_tol`` and ``aligned``), against ``tol``."""
        sides = self.one_sided or {}
        return {"compare_max": self.max, "compare_mean": self.mean, "compare_p95": self.p95,
                "compare_p99": self.p99, "beyond_tol": self.verdict(tol).beyond,
                "compare_a_to_b": sides.get("a_to_b", {}).get("max"),
                "compare_b_to_a": sides.get("b_to_a", {}).get("max"),
                "aligned": "" if self.motion is None else motion_text(self.motion)}

    def figures(self) -> dict[str, Any]:
        """The distances as ``--json`` and the summaries write them (the comparison's unit)."""
        out: dict[str, Any] = {"mode": self.mode, "max": self.max, "mean": self.mean,
                               "rms": self.rms, "p95": self.p95, "p99": self.p99,
                               "diagonal": self.diagonal, "farthest": self.farthest}
        if self.one_sided is not None:
            out.update(self.one_sided)
        if self.motion is not None:
            out["motion"] = self.motion
        return out


_FIGURES = ("max", "mean", "rms", "p95", "p99")


def motion_text(motion: dict[str, Any]) -> str:
    """A rigid motion in words, rounding off below 1e-12 (``-7e-17`` is 0).

    Examples
    --------
    >>> motion_text({"angle": 30.0, "axis": [1, -7e-17, 0], "translation": [3, 0, 1e-20]})
    'turned 30 degrees about (1, 0, 0), moved by (3, 0, 0)'
    """
    def text(values, digits):
        return ", ".join(format(x if abs(x) > 1e-12 else 0.0, digits) for x in values)

    return (f"turned {motion['angle']:.4g} degrees about ({text(motion['axis'], '.3g')}), "
            f"moved by ({text(motion['translation'], '.4g')})")


def compare_meshes(a: Mesh | tuple, b: Mesh | tuple, align: str = "none") -> Comparison:
    """Distances between meshes ``a`` and ``b`` (Mesh, or ``(V, F)``), in model units.

    Same topology: per-vertex distances ``|a_i - b_i|`` (max, mean, RMS, 95th and 99th
    percentiles). Otherwise: every vertex's distance to the other surface, both ways; ``max``
    is the larger one-sided maximum (the symmetric Hausdorff distance at the vertices), and
    each one-sided distance is kept (``one_sided``). ``align="rigid"`` (same topology only)
    first moves B by the rigid motion that brings it closest to A (least squares) and keeps
    that motion (``motion``).

    Examples
    --------
    >>> a = Mesh.from_arrays(np.array([[0., 0, 0], [3, 0, 0], [0, 4, 0]]), np.array([[0, 1, 2]]))
    >>> c = compare_meshes(a, a.with_vertices(a.vertices + [0, 0, 0.5]))
    >>> c.mode, c.max, c.diagonal, c.scaled(True).max, c.verdict(1.0).within
    ('per-vertex', 0.5, 5.0, 0.1, True)
    >>> round(compare_meshes(a, a.with_vertices(a.vertices + [0, 0, 0.5]), "rigid").max, 12)
    0.0
    """
    a, b = _as_mesh(a, "a"), _as_mesh(b, "b")
    if align not in ALIGNMENTS:
        raise ValueError(f"align must be one of {', '.join(ALIGNMENTS)}, got {align!r}")
    diagonal = float(np.linalg.norm(np.ptp(a.vertices, axis=0)))
    same = same_topology(a, b)
    motion = None
    if align == "rigid":
        if not same:
            raise UsageProblem("--align rigid needs meshes with the same vertices and faces "
                               "(vertex i of A is vertex i of B)")
        motion = rigid_motion(a.vertices, b.vertices)
        b = moved(b, motion)
    if same:
        d = np.linalg.norm(a.vertices - b.vertices, axis=1)
        sides = None
    else:
        Fa, Fb = a.triangles()[0], b.triangles()[0]
        ab = np.sqrt(igl.point_mesh_squared_distance(a.vertices, b.vertices, Fb)[0])
        ba = np.sqrt(igl.point_mesh_squared_distance(b.vertices, a.vertices, Fa)[0])
        d = np.concatenate([ab, ba])
        sides = {"a_to_b": _stats(ab), "b_to_a": _stats(ba), "sampling": SURFACE_SAMPLING}
    stats = _stats(d)
    return Comparison("per-vertex" if same else "surface", stats["max"], stats["mean"],
                      stats["rms"], diagonal, _farthest(d, a, b), d, p95=stats["p95"],
                      p99=stats["p99"], one_sided=sides, motion=motion)


def _as_mesh(m, name):
    if isinstance(m, Mesh):
        return m
    if isinstance(m, tuple) and len(m) == 2:
        return Mesh.from_arrays(*m)
    raise TypeError(f"{name} must be a Mesh or a (V, F) pair, got {type(m).__name__}")


def _stats(d):
    if not d.size:
        return {"max": 0.0, "mean": 0.0, "rms": 0.0, "p95": 0.0, "p99": 0.0, "samples": 0}
    p95, p99 = np.percentile(d, [95, 99])
    return {"max": float(d.max()), "mean": float(d.mean()), "rms": float(np.sqrt(np.mean(d * d))),
            "p95": float(p95), "p99": float(p99), "samples": int(d.size)}


def _farthest(d, a, b):
    """Which vertex is farthest from the other mesh, and where it is."""
    if not d.size:
        return None
    k = int(np.argmax(d))
    mesh, V = ("a", a.vertices) if k < len(a.vertices) else ("b", b.vertices)
    k = k if mesh == "a" else k - len(a.vertices)
    return {"mesh": mesh, "vertex": k, "position": V[k].tolist()}
