"""How a job ended: a status, its exit code, and the figures every report of it shows (the
batch's console table, ``summary.csv`` / ``summary.json``, the HTML report, JUnit)."""
import enum
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..runtime import exit_codes

if TYPE_CHECKING:
    from ..io.handles import Constraints
    from ..io.mesh import Mesh
    from .comparison import Comparison, Expect

#: the columns of a batch's ``summary.csv`` (``summary.json`` holds ``warnings`` as a list;
#: ``stop``: the solve's :class:`~srarap_cli.solver.stop.StopReason`, empty for a job that
#: never reached the solver)
#: ``compare_*``, ``beyond_tol``: the distances to the golden (the unit of ``tol``;
#: ``compare_a_to_b`` / ``compare_b_to_a``: the largest one-sided distances, golden to output
#: and back, where the meshes do not share vertices); ``aligned``: the rigid motion applied
#: first (``align: rigid``); ``golden``: ``created`` or ``updated`` where the run wrote it)
SUMMARY_FIELDS = ("job", "status", "stop", "iterations", "energy", "seconds", "compare_max",
                  "message", "compare_mean", "tol", "exit_code", "compare_p95", "compare_p99",
                  "beyond_tol", "compare_a_to_b", "compare_b_to_a", "aligned", "golden",
                  "warnings")
#: how warnings are joined in one CSV cell
WARNING_JOIN = " | "


class JobStatus(enum.Enum):
    """A job's outcome, in the order a reviewer needs to see them."""

    FAILED = "failed"
    REGRESSED = "regressed"
    NO_GOLDEN = "no-golden"
    NOT_CONVERGED = "not-converged"
    INTERRUPTED = "interrupted"
    OK = "ok"
    UP_TO_DATE = "up-to-date"

    @property
    def exit_code(self) -> int:
        """The exit code ``srarap deform`` / ``compare`` gives for the same outcome (a failed
        job's own code is on its result; 1 stands for one unknown)."""
        return _EXIT_CODES[self]

    @property
    def passed(self) -> bool:
        """The job did what it was asked (solved, or is up to date)."""
        return self in (JobStatus.OK, JobStatus.UP_TO_DATE)

    @property
    def unfinished(self) -> bool:
        """The job ended without a result (a JUnit ``error``): failed or interrupted."""
        return self in (JobStatus.FAILED, JobStatus.INTERRUPTED)

    @property
    def fails_batch(self) -> bool:
        """The job makes its batch fail (exit 8): failed, regressed or without its golden."""
        return self in (JobStatus.FAILED, JobStatus.REGRESSED, JobStatus.NO_GOLDEN)


def batch_exit_code(statuses: Iterable["JobStatus"]) -> int:
    """A finished batch's exit code from its jobs' statuses: 8 when any failed, regressed or
    has no golden, else 3 when any did not converge, else 0 (a stopped batch exits with its
    signal's)."""
    statuses = list(statuses)
    if any(s.fails_batch for s in statuses):
        return exit_codes.BATCH_FAILED
    return exit_codes.NOT_CONVERGED if JobStatus.NOT_CONVERGED in statuses else exit_codes.OK


_EXIT_CODES = {JobStatus.OK: exit_codes.OK, JobStatus.UP_TO_DATE: exit_codes.OK,
               JobStatus.NOT_CONVERGED: exit_codes.NOT_CONVERGED,
               JobStatus.REGRESSED: exit_codes.BEYOND_TOLERANCE,
               JobStatus.NO_GOLDEN: exit_codes.BATCH_FAILED,
               JobStatus.INTERRUPTED: exit_codes.INTERRUPTED,
               JobStatus.FAILED: exit_codes.INTERNAL_ERROR}


@dataclass
class Seen:
    """What a job's run saw, kept in the process that ran it for the report's pictures
    (:func:`srarap_cli.tasks.batch.run.job_pictures`); never sent between processes.

    Attributes
    ----------
    mesh : Mesh, the rest mesh read; deformed : Mesh, the mesh written (or solved, unwritten)
    constraints : Constraints, the handles resolved on the mesh
    log : list of dict, the solve's per-iteration log rows
    golden : (Comparison, Expect), the distances to the golden and its gates
    recorded_seconds : float, the seconds an up-to-date job's recorded run took
    """

    mesh: "Mesh | None" = None
    deformed: "Mesh | None" = None
    constraints: "Constraints | None" = None
    log: list[dict[str, Any]] | None = None
    golden: "tuple[Comparison, Expect] | None" = None
    recorded_seconds: float | None = None


@dataclass
class JobResult:
    """One job's result.

    Attributes
    ----------
    job : str, the job's name
    status : JobStatus
    exit_code : int, what ``srarap deform`` exits with for this outcome
    message : str, one line on why it failed, regressed or wrote no mesh
    warnings : list of str, every warning of the run (handle file, mesh, solver, output)
    stop : str, the solve's stop reason; iterations, energy: its figures (None unsolved)
    seconds : float, the job's wall time
    compare_max, compare_mean, compare_p95, compare_p99 : distances to the golden mesh, in
        the unit of ``tol``
    compare_a_to_b, compare_b_to_a : the largest one-sided distances (A the golden), where
        the meshes do not share vertices
    tol : the tolerance; beyond_tol : the fraction of vertices beyond it
    aligned : the rigid motion the result was moved by first, in words, or ""
    golden : ``created`` or ``updated`` where this run wrote the golden, else ""
    solved : bool, the solver ran in this run (False: an unchanged job's recorded result)
    written : str, the output mesh written, or None
    peaks : dict stage -> bytes, peak memory per stage (``-v``)
    solve : DeformResult, settings : Settings, the solve and its settings (in the process
        that ran it; not sent between processes)
    seen : Seen, what the report's pictures are drawn from
    pictures : dict name -> base64 PNG, the report's pictures of the job
    """

    job: str
    status: JobStatus
    exit_code: int
    message: str = ""
    warnings: list[str] = field(default_factory=list)
    stop: str = ""
    iterations: int | None = None
    energy: float | None = None
    seconds: float | None = None
    compare_max: float | None = None
    compare_mean: float | None = None
    tol: float | None = None
    compare_p95: float | None = None
    compare_p99: float | None = None
    beyond_tol: float | None = None
    compare_a_to_b: float | None = None
    compare_b_to_a: float | None = None
    aligned: str = ""
    golden: str = ""
    solved: bool = False
    written: str | None = None
    peaks: dict[str, int | None] = field(default_factory=dict, repr=False)
    solve: Any = field(default=None, repr=False)
    settings: Any = field(default=None, repr=False)
    seen: Seen = field(default_factory=Seen, repr=False)
    pictures: dict[str, str] = field(default_factory=dict, repr=False)

    def row(self) -> dict[str, Any]:
        """The summary row: :data:`SUMMARY_FIELDS`, ``warnings`` a list."""
        return {"job": self.job, "status": self.status.value, "stop": self.stop,
                "iterations": self.iterations, "energy": self.energy, "seconds": self.seconds,
                "compare_max": self.compare_max, "message": self.message,
                "compare_mean": self.compare_mean, "tol": self.tol, "exit_code": self.exit_code,
                "warnings": list(self.warnings), "compare_p95": self.compare_p95,
                "compare_p99": self.compare_p99, "beyond_tol": self.beyond_tol,
                "compare_a_to_b": self.compare_a_to_b, "compare_b_to_a": self.compare_b_to_a,
                "aligned": self.aligned, "golden": self.golden}

    def shipped(self) -> "JobResult":
        """This result without what stays in the process that ran it (the solve's arrays),
        as a worker sends it back."""
        self.solve = self.settings = None
        self.seen = Seen()
        return self
