"""A batch as one job: :class:`BatchJob` (a manifest, an output folder and how to run it),
:func:`run_batch` and its :class:`BatchOutcome`, as every command's wing has them; the jobs
themselves run in :mod:`.run`."""
import dataclasses
import os
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from typing import Any

from ...runtime.errors import OutputError
from ...runtime.paths import hold
from ...runtime.signals import block
from .. import job_fields as fields
from ..comparison import GOLDEN_MODES
from ..job_status import JobResult, batch_exit_code
from ..preflight import check_output_path
from .manifest import SUMMARIES, check_goldens, check_outputs, load_manifest
from .rows import BatchInterrupted
from .run import run_jobs
from .summary import write_reports, write_summaries

#: what says a long job's stages: a context made from the job's name
Heartbeat = Callable[[str], AbstractContextManager[Any]]


@dataclass(frozen=True)
class BatchJob:
    """One run of a manifest, as ``srarap batch`` takes it.

    Attributes
    ----------
    manifest : str
        The manifest's path (YAML or JSON).
    out : str
        The folder of the jobs' outputs and of ``summary.csv`` / ``summary.json``.
    workers : int
        Worker processes (1: the jobs run in this process).
    scheduler : str, optional
        ``local`` or a Dask scheduler's address.
    keep_unconverged : bool
        Write the mesh of a job that did not converge.
    goldens : str
        ``check``, ``update`` or ``accept`` (see ``batch --update-goldens``).
    threads : int, optional
        Each job's threads, at most its share of the CPUs.
    settings : mapping
        Setting values laid over every job's (the command line's ``strict`` and ``allow``).
    report, junit, markdown, metrics : str, optional
        The reports to write too: HTML, JUnit XML, Markdown, OpenMetrics.
    heartbeat : callable, optional
        ``heartbeat(name)``: a context that says a long job's stages (a picklable
        function: the workers call it).
    """

    manifest: str
    out: str = "."
    workers: int = 1
    scheduler: str | None = None
    keep_unconverged: bool = False
    goldens: str = "check"
    threads: int | None = None
    settings: Mapping[str, Any] = field(default_factory=dict)
    report: str | None = None
    junit: str | None = None
    markdown: str | None = None
    metrics: str | None = None
    heartbeat: Heartbeat | None = None

    def __post_init__(self) -> None:
        fields.text(self, "manifest")
        fields.text(self, "out")
        for name in ("scheduler", "report", "junit", "markdown", "metrics"):
            fields.text(self, name, optional=True)
        fields.count(self, "workers")
        fields.count(self, "threads", optional=True)
        fields.choice(self, "goldens", GOLDEN_MODES)
        fields.flag(self, "keep_unconverged")
        if not isinstance(self.settings, Mapping):
            raise TypeError("BatchJob.settings must be a mapping of settings")


@dataclass
class BatchOutcome:
    """What a batch did.

    Attributes
    ----------
    rows : list of JobResult
        The jobs' results, in manifest order.
    out : str
        The output folder, as held for the run (its real path).
    stopped : BaseException or None
        The exception of the signal that stopped the batch.
    failure : Exception or None
        An error after the summary was written (a report that could not be written); the
        caller raises it once it has said the rows.
    """

    rows: list[JobResult]
    out: str
    stopped: BaseException | None = None
    failure: Exception | None = None

    @property
    def exit_code(self) -> int:
        """The exit code of a batch that ran to its end (see :func:`batch_exit_code`)."""
        return batch_exit_code(r.status for r in self.rows)


def run_batch(batch: BatchJob) -> BatchOutcome:
    """Run ``batch``: its checks before any job (the reports' paths, the goldens it may
    write, outputs that would land on inputs), the jobs (a failing job never stops the
    others), then ``summary.csv`` / ``summary.json`` and the reports asked for.

    A signal stops the jobs; the outcome says which (``stopped``) and holds the rows of the
    jobs that finished, the summary written all the same.

    Raises InputError, UsageProblem or OutputError for a run that cannot start.
    """
    _check_reports(batch)
    # over the manifest's defaults and each job's settings, as deform's over a handle file's
    jobs = [dataclasses.replace(job.over(batch.settings), goldens=batch.goldens)
            for job in load_manifest(batch.manifest)]
    if batch.goldens != "check":
        check_goldens(jobs, batch.manifest)
    check_outputs(jobs, batch.out, batch.manifest)
    try:
        os.makedirs(batch.out, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{batch.out}: cannot create folder: {exc.strerror}") from None
    for name in SUMMARIES:  # before solving, as deform checks its -o
        check_output_path(os.path.join(batch.out, name), None, "summary")
    held = hold(batch.out)  # every file of the run is written there, whatever -o names later
    outcome = BatchOutcome([], held)
    try:
        outcome.rows = run_jobs(jobs, held, batch.workers, batch.scheduler,
                                batch.keep_unconverged, pictures=batch.report is not None,
                                threads=batch.threads, heartbeat=batch.heartbeat)
    except BatchInterrupted as exc:  # the workers are stopped: say what finished
        outcome.rows, outcome.stopped = exc.rows, exc.signal
        # the summary is what is left to do: a second Ctrl-C or SIGTERM (a CI runner's
        # timeout sends more than one) must not cost it; the exit code says stopped anyway
        block()
    # the summary first, on its own: a report that cannot be written (a full disk) must not
    # cost the account of the jobs whose outputs are on disk
    write_summaries(outcome.rows, held)
    try:
        write_reports(outcome.rows, batch.manifest, batch.report, batch.junit, batch.markdown,
                      batch.metrics)
    except OutputError as exc:
        outcome.failure = exc
    return outcome


def _check_reports(batch):
    """Refuse, before any job, a report that could not be written."""
    if batch.report is not None:
        check_output_path(batch.report, (".html", ".htm"), "--report")
    if batch.junit is not None:
        check_output_path(batch.junit, (".xml",), "--junit")
    for path, what in ((batch.markdown, "--summary-md"), (batch.metrics, "--metrics")):
        if path is not None:
            check_output_path(path, None, what)
