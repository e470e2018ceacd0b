"""The result of every solve: :class:`DeformResult`, with a :class:`MultiresPart` when the
solve went through a coarse mesh (paper section 7)."""
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..runtime import memory
from .stop import StopReason

#: the multiresolution stages by key, as the summary names them
STAGE_NAMES = {"simplify": "simplify", "coarse_precompute": "coarse setup",
               "factor": "fine setup", "coarse_solve": "coarse solve", "transfer": "transfer",
               "fine_solve": "fine solve", "fine_start": "full-resolution start",
               "fine_iterations": "full-resolution iterations"}


@dataclass(repr=False)
class MultiresPart:
    """How a multiresolution solve got its result.

    Attributes
    ----------
    coarse_vertices : int
        Vertices of the coarse mesh (a subset of the full mesh's).
    cache_hit : bool
        The coarse mesh came from the cache folder.
    iterations : int
        Iterations of the coarse solve (and of the coarser ones inside it); 0 for a warm
        solve, which goes straight to full resolution.
    stop_reason : StopReason or None
        Why the coarse solve stopped (None: a warm solve).
    transfer : bool
        The result is the paper's transfer of the coarse solve (rotors spread
        harmonically, one Poisson solve), not iterated at full resolution; the log then
        ends with coarse iterations.
    full_energy : dict
        ``membrane``, ``bending``, ``total`` of the returned full-resolution positions and
        rotors.
    start_energy : dict
        Transfer only: the full-resolution energies of the rest shape with the constrained
        vertices at their targets (what the approximation is judged against).
    stages : dict
        Seconds per stage (keys of :data:`STAGE_NAMES`); the simplification and the
        full-resolution setup run side by side, so they add up to more than ``wall``.
    memory : dict
        Peak resident bytes per stage (``setup``, then the solve's; None where the platform
        cannot tell, see :mod:`srarap_cli.runtime.memory`).
    wall : float
        Wall seconds of the solve (setup excluded).
    """

    coarse_vertices: int
    cache_hit: bool
    iterations: int = 0
    stop_reason: StopReason | None = None
    transfer: bool = False
    full_energy: dict = field(default_factory=dict)
    start_energy: dict = field(default_factory=dict)
    stages: dict = field(default_factory=dict)
    memory: dict = field(default_factory=dict)
    wall: float = 0.0

    @property
    def converged(self) -> bool:
        """The coarse solve passed its stopping test."""
        return self.stop_reason is StopReason.CONVERGED

    def __repr__(self) -> str:
        how = "transfer" if self.transfer else "refine"
        return (f"MultiresPart({how}, {self.coarse_vertices} coarse vertices, "
                f"{self.iterations} coarse iterations, {self.stop_reason})")


@dataclass(repr=False)  # one line, not every array and log row (see __repr__)
class DeformResult:
    """Outcome of a solve (:meth:`Deformer.solve`, :func:`srarap_cli.deform`, ...).

    Attributes
    ----------
    positions : (n, 3) float array
        The deformed positions.
    rotors : (n, 4) float array
        Unit quaternions (w, x, y, z) of the vertex cells.
    log : list of dict
        One row per iteration (0 is the start), keys ``solve_log.LOG_FIELDS``; a
        multiresolution solve's holds the coarse iterations first (``step`` prefixed
        ``coarse-``).
    stop_reason : StopReason
        Why the solve stopped (see :mod:`srarap_cli.solver.stop`).
    iterations : int
        Local/global iterations run at full resolution.
    stop_detail : str
        For a solve stopped unconverged: which stopping test still failed, with its
        numbers.
    faces : (f, 3) int array or None
        The mesh's triangles, when the result came from :func:`srarap_cli.deform` on a mesh.
    warnings : list of str
        What the input or the solve found worth a warning.
    multires : MultiresPart or None
        The coarse solve's part (None: solved at full resolution only).
    converged : bool
        Property: the stopping test passed at full resolution.
    complete : bool
        Property: the solve ended as asked (converged, or ``tol`` 0 ran the iterations
        asked; for the multiresolution transfer, its coarse solve did).
    approximate : bool
        Property: the result is the paper's transfer of a coarse solve.
    coarse_iterations : int
        Property: iterations on coarse meshes (0 without multires).

    Examples
    --------
    >>> import numpy as np, srarap_cli
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> r = srarap_cli.deform(V, F, [0, 1, 2], V + 1.0)
    >>> repr(r)[:38]
    'DeformResult(converged, 1 iterations, '
    >>> bool(np.allclose(r.positions, V + 1.0)), r.multires is None
    (True, True)
    """

    positions: np.ndarray
    rotors: np.ndarray
    log: list[dict]
    stop_reason: StopReason
    iterations: int
    stop_detail: str = ""
    faces: np.ndarray | None = None
    warnings: list[str] = field(default_factory=list)
    multires: MultiresPart | None = None

    def to_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(V, F)``: the deformed positions (n, 3) and the triangles (f, 3)."""
        if self.faces is None:
            raise ValueError("this result carries no faces: pair positions with your F")
        return self.positions, self.faces

    def to_trimesh(self) -> Any:
        """A ``trimesh.Trimesh`` of the deformed shape (needs trimesh installed)."""
        import trimesh

        V, F = self.to_arrays()
        return trimesh.Trimesh(vertices=V, faces=F, process=False)

    def to_meshio(self) -> Any:
        """A ``meshio.Mesh`` of the deformed shape (needs meshio installed)."""
        import meshio

        V, F = self.to_arrays()
        return meshio.Mesh(V, [("triangle", F)])

    @property
    def approximate(self) -> bool:
        return self.multires is not None and self.multires.transfer

    @property
    def coarse_iterations(self) -> int:
        return 0 if self.multires is None else self.multires.iterations

    @property
    def converged(self) -> bool:
        return self.stop_reason is StopReason.CONVERGED

    @property
    def complete(self) -> bool:
        part = self.multires
        if part is not None and part.transfer:
            return part.stop_reason is not None and part.stop_reason.complete
        return self.stop_reason.complete

    def energies(self) -> dict[str, float]:
        """``membrane``, ``bending`` and ``total`` energy of the returned shape."""
        if self.multires is not None:
            return dict(self.multires.full_energy)
        return {k: self.log[-1][k] for k in ("membrane", "bending", "total")}

    @property
    def energy(self) -> float:
        return self.energies()["total"]

    @property
    def seconds(self) -> float:
        """Wall time of the solve."""
        return self.log[-1]["seconds"] if self.multires is None else self.multires.wall

    def report_lines(self) -> list[str]:
        """Lines a command prints about how the result was obtained: for a multiresolution
        solve, ``srarap: multires: 5002 of 737986 vertices; simplify 1.20 s, ...`` and the
        peak memory per stage where measured."""
        part = self.multires
        if part is None:
            return []
        cached = " (coarse mesh from cache)" if part.cache_hit else ""
        times = ", ".join(f"{STAGE_NAMES.get(k, k)} {v:.2f} s" for k, v in part.stages.items())
        lines = [f"srarap: multires: {part.coarse_vertices} of {len(self.positions)} "
                 f"vertices{cached}; {times}"]
        peaks = memory.gigabytes({STAGE_NAMES.get(k, k): v for k, v in part.memory.items()})
        return lines + ([f"srarap: multires: peak memory per stage: {peaks}"] if peaks else [])

    def __repr__(self) -> str:
        """One line: how the solve ended, its size and energy (the arrays and the log are
        attributes, not printed: a notebook cell ending in a result stays readable)."""
        coarse = f" (+ {self.coarse_iterations} coarse)" if self.coarse_iterations else ""
        state = "converged" if self.converged else str(self.stop_reason)
        return (f"DeformResult({state}, {self.iterations} iterations{coarse}, "
                f"energy {self.energy:.6g}, {len(self.positions)} vertices, "
                f"{len(self.warnings)} warnings)")
