"""The jobs of a manifest, run: up-to-date checks, parallel workers, their rows (the batch
as one job, with its summary: :mod:`.job`).

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
import functools
import os
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

from ...io.handles import load_handles
from ...io.mesh import read_mesh
from ...runtime.parallel import at_most, available_cpus, using_threads, worker_share
from ...runtime.signals import Terminated
from ..deform import JobResult, run_job_safely
from ..job_status import Seen
from ..pictures import difference_picture, energy_picture, shape_picture
from ..reports import encode_png
from .manifest_job import ManifestJob
from .on_dask import run_on_dask
from .rows import BatchInterrupted, deform_job, interrupted_row, lost_row, solved_since
from .worker_pool import PoolStopped, run_in_processes

#: what says a long job's stages: a context made from the job's name
Heartbeat = Callable[[str], AbstractContextManager[Any]]

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
    with beat, at_most(threads or available_cpus()), using_threads(threads):
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


