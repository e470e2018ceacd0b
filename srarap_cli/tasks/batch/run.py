"""Many deformations from one manifest: up-to-date checks, parallel workers, a summary.

A manifest (YAML or JSON) lists jobs; paths are relative to the manifest::

    defaults: {method: sr-linear-sym, tol: 1.0e-6}      # solver settings for every job
    jobs:
      - name: bar-twist
        mesh: ../sample_meshes/bar.obj
        handles: ../configs/bar-twist.yaml
        output: bar-twist.obj                           # relative to the output folder
        settings: {max_iter: 500}                       # this job only
        expect: {golden: golden/bar-twist.obj, tol: 1.0e-9, relative: true,
                 energy_rtol: 1.0e-6, max_iterations: 50}   # gates: see comparison.gates

A job is up to date when its output exists and the sidecar ``<output>.srarap.json`` records
the same fingerprint (content of the mesh, the handle file and every file it names, settings,
srarap version).
"""
import contextlib
import dataclasses
import functools
import os
import time
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from typing import Any

from ...io.handles import load_handles
from ...io.mesh import read_mesh
from ...runtime.errors import OutputError
from ...runtime.parallel import at_most, using_threads, worker_share
from ...runtime.paths import hold
from ...runtime.signals import Terminated, block
from ..deform import JobResult, run_job_safely
from ..job_status import Seen, batch_exit_code
from ..pictures import difference_picture, energy_picture, shape_picture
from ..preflight import check_output_path
from ..reports import encode_png
from .manifest import SUMMARIES, check_goldens, check_outputs, load_manifest
from .manifest_job import ManifestJob
from .on_dask import run_on_dask
from .rows import BatchInterrupted, deform_job, interrupted_row, lost_row, solved_since
from .summary import write_reports, write_summaries
from .worker_pool import PoolStopped, run_in_processes

Heartbeat = Callable[[str], AbstractContextManager[Any]]


@dataclass(frozen=True)
class BatchJob:
    """One run of a manifest, as ``srarap batch`` takes it.

    Attributes
    ----------
    manifest : str, the manifest's path (YAML or JSON)
    out : str, the folder of the jobs' outputs and of ``summary.csv`` / ``summary.json``
    workers : int, worker processes (1: the jobs run in this process)
    scheduler : str, optional, ``local`` or a Dask scheduler's address
    keep_unconverged : bool, write the mesh of a job that did not converge
    goldens : str, ``check``, ``update`` or ``accept`` (:data:`..deform.golden.GOLDEN_MODES`)
    threads : int, optional, each job's threads, at most its share of the CPUs
    settings : mapping, setting values laid over every job's (the command line's
        ``strict`` and ``allow``)
    report, junit, markdown, metrics : str, optional, the reports to write too
    heartbeat : callable(name) -> context, optional, what says a long job's stages (a
        picklable function: the workers call it)
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


@dataclass
class BatchOutcome:
    """What a batch did: ``rows`` (the jobs' results, in manifest order), ``out`` (the
    output folder as held), ``stopped`` (the signal's exception that stopped it, else None)
    and ``failure`` (an error that came after the summary was written: a report that could
    not be written; the caller raises it once it has said the rows)."""

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


def run_job(job: ManifestJob, out_dir: str, keep_unconverged: bool = False,
            pictures: bool = False, threads: int | None = None,
            heartbeat: Heartbeat | None = None) -> JobResult:
    """Run one job of a manifest through the job runner (:func:`.job.run_job_safely`);
    never raises. With ``pictures``, the result carries the report's pictures of the job
    (see :func:`job_pictures`).

    A job that does not converge writes its record (the status, so a rerun reports it
    without solving again) but not its mesh, unless ``keep_unconverged``: as ``srarap
    deform``. ``threads``: the threads its solve runs, and the most it may run (its own
    ``threads`` setting, where smaller, stands). ``heartbeat(name)``: a context that says the
    job's stages while it runs long (a picklable function: workers call it)."""
    spec = deform_job(job, out_dir, keep_unconverged)
    beat = heartbeat(job.name) if heartbeat is not None else contextlib.nullcontext()
    with beat, at_most(worker_share(1, threads)), using_threads(threads):
        result = run_job_safely(spec)
    if pictures:  # after the seconds: the solve's, not the drawing's
        result.pictures = job_pictures(job, spec.output, result.seen)
    return result.shipped()


def job_pictures(job: ManifestJob, out: str, seen: Seen) -> dict[str, str]:
    """The report's pictures of a job (base64 PNG by name: ``shape``, ``difference``,
    ``energy``), drawn from what the job solved or, for one up to date, from its files;
    those without their data are left out (a failed job's, a missing golden's); a drawing
    that fails leaves ``note`` instead, which the report shows."""
    out_pictures: dict[str, str] = {}
    try:
        mesh = seen.mesh if seen.mesh is not None else read_mesh(job.mesh)
        deformed = seen.deformed
        if deformed is None and os.path.exists(out):
            deformed = read_mesh(out)
        if deformed is None or len(deformed.vertices) != len(mesh.vertices):
            return out_pictures
        constraints = (seen.constraints if seen.constraints is not None
                       else load_handles(job.handles, mesh.vertices, any_rate=True))
        out_pictures["shape"] = encode_png(shape_picture(mesh, deformed, constraints))
        if seen.golden is not None:
            found, expect = seen.golden
            out_pictures["difference"] = encode_png(difference_picture(
                mesh, deformed, found.of_b(len(deformed.vertices)), expect.tol,
                found.scale))
        if seen.log:
            out_pictures["energy"] = encode_png(energy_picture(seen.log))
    except Exception as exc:  # noqa: BLE001 -- the report says why, the job's result stands
        out_pictures["note"] = f"pictures not drawn: {type(exc).__name__}: {exc}"
    return out_pictures


def run_jobs(jobs: list[ManifestJob], out_dir: str, workers: int = 1,
             scheduler: str | None = None, keep_unconverged: bool = False,
             pictures: bool = False, threads: int | None = None,
             heartbeat: Heartbeat | None = None) -> list[JobResult]:
    """Run jobs: on a Dask cluster at ``scheduler``, else in ``workers`` local processes
    (in this process when 1). Rows come back in manifest order. ``keep_unconverged``: see
    :func:`run_job`. Each job's solve runs ``threads`` threads (default
    ``$SRARAP_THREADS``, else its share of the CPUs), never more than its share, so that
    workers times threads stays within the CPUs
    (:func:`~srarap_cli.runtime.parallel.worker_share`).

    The Dask workers must see the same files as this process (a shared file system).
    ``heartbeat``: see :func:`run_job`.
    """
    since = time.time()
    run = functools.partial(run_job, out_dir=out_dir, keep_unconverged=keep_unconverged,
                            pictures=pictures, threads=worker_share(workers, threads),
                            heartbeat=heartbeat)
    unfinished = functools.partial(interrupted_row, out_dir=out_dir,
                                   keep_unconverged=keep_unconverged, since=since)
    try:
        rows = _rows(jobs, run, workers, scheduler, unfinished)
    except BatchInterrupted as exc:
        exc.rows = [solved_since(row, job, out_dir, since) for row, job in zip(exc.rows, jobs)]
        raise
    return [solved_since(row, job, out_dir, since) for row, job in zip(rows, jobs)]


def _rows(jobs, run, workers, scheduler, unfinished):
    if scheduler is not None:
        return run_on_dask(jobs, run, scheduler, workers, unfinished)
    if workers <= 1:
        rows: list[JobResult] = []
        try:
            for job in jobs:
                rows.append(run(job))
        except (KeyboardInterrupt, Terminated) as exc:
            raise BatchInterrupted(rows + [unfinished(j) for j in jobs[len(rows):]],
                                   exc) from None
        return rows
    return _run_in_processes(jobs, run, workers, unfinished)


def _run_in_processes(jobs, run, workers, unfinished):
    """Jobs in ``workers`` processes (:mod:`.worker_pool`), rows in manifest order; a signal
    raises :class:`BatchInterrupted` with the rows of the jobs that finished."""
    try:
        return run_in_processes(jobs, run, workers, lost_row)
    except PoolStopped as exc:
        raise BatchInterrupted([exc.rows.get(k) or unfinished(job)
                                for k, job in enumerate(jobs)], exc.signal) from None


