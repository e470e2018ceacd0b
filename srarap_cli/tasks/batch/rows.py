"""A batch's results of jobs that did not finish (a signal stopped the batch, a worker process
died), and the interruption that carries every job's result."""
import os

from ...runtime import exit_codes
from ...runtime.signals import Terminated
from ..deform import DeformJob, JobResult, JobStatus, recorded_result, sidecar_path
from .manifest_job import ManifestJob
from .worker_pool import death_note


class BatchInterrupted(BaseException):
    """SIGINT or SIGTERM stopped a batch: ``rows`` are the jobs' results, in manifest order,
    of the jobs that finished and of the others (``status`` ``interrupted``); ``signal`` the
    exception the signal raised."""

    def __init__(self, rows: list[JobResult], signal: BaseException) -> None:
        super().__init__("interrupted")
        self.rows, self.signal = rows, signal
        code = exit_codes.TERMINATED if isinstance(signal, Terminated) else exit_codes.INTERRUPTED
        for row in rows:  # a job SIGTERM stopped says 143, as the batch's exit does (not 130)
            if row.status is JobStatus.INTERRUPTED:
                row.exit_code = code


def deform_job(job: ManifestJob, out_dir: str, keep_unconverged: bool = False) -> DeformJob:
    """The :class:`~.job.DeformJob` of a manifest's job (see :mod:`.manifest`), writing
    under ``out_dir`` and keeping its record there."""
    return DeformJob(job.mesh, job.handles, os.path.join(out_dir, job.output),
                     settings=job.settings, name=job.name,
                     keep_unconverged=keep_unconverged, expect=job.expect, record=True,
                     inside=out_dir, goldens=job.goldens, golden_root=job.golden_root)


def interrupted_row(job: ManifestJob, out_dir: str | None = None, keep_unconverged: bool = False,
                    since: float | None = None) -> JobResult:
    """The result of a job a signal stopped before its result came back. Where its record
    under ``out_dir`` matches its inputs, the files on disk are that run's: the job is
    reported as the record says (committed after ``since``, the batch's start: finished as
    the batch was stopped), else ``interrupted``."""
    spec = None if out_dir is None else deform_job(job, out_dir, keep_unconverged)
    done = None if spec is None else recorded_result(spec)
    if spec is not None and done is not None:
        if since is not None and _recorded_since(spec, since):
            done.solved, done.message = True, "finished as the batch was stopped"
            if done.status is JobStatus.UP_TO_DATE:
                done.status = JobStatus.OK
        return done
    return JobResult(job.name, JobStatus.INTERRUPTED, JobStatus.INTERRUPTED.exit_code,
                     message="not finished: the batch was interrupted")


def solved_since(row: JobResult, job: ManifestJob, out_dir: str, since: float) -> JobResult:
    """``row``, an ``up-to-date`` job's, as ``ok`` where its record was written after
    ``since`` (the batch's start): this batch solved it, and a second run of it found its
    own outputs (a Dask worker that a signal or a crash stopped after the commit, its task
    run again). Other rows as they are."""
    if row.status is JobStatus.UP_TO_DATE and _recorded_since(deform_job(job, out_dir), since):
        row.status, row.exit_code, row.solved = JobStatus.OK, JobStatus.OK.exit_code, True
    return row


def _recorded_since(spec: DeformJob, since: float) -> bool:
    """Whether ``spec``'s record was written at ``since`` (the batch's start) or later."""
    try:
        return os.path.getmtime(sidecar_path(spec.output)) >= since
    except OSError:
        return False


def lost_row(job: ManifestJob, exitcode: int) -> JobResult:
    """The result of a job whose worker process died when it ran alone."""
    return unfinished_row(job, death_note(exitcode),
                          128 - exitcode if exitcode < 0 else exitcode or 1)


def unfinished_row(job: ManifestJob, reason: str, exit_code: int) -> JobResult:
    """The result of a job that failed without a result of its own (its process died)."""
    return JobResult(job.name, JobStatus.FAILED, exit_code, message=f"not finished: {reason}")
