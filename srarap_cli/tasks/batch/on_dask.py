"""A batch on a Dask cluster (``batch --scheduler``): a local one srarap starts, or one at an
address; rows in manifest order, a job Dask gave up on a failed row."""
import functools
import logging
import os
from collections.abc import Callable

from ...runtime.environment import environ_changed
from ...runtime.errors import InputError
from ...runtime.paths import hold
from ...runtime.signals import Terminated, block
from ...runtime.threads import worker_processes
from ..job_status import JobResult
from .manifest_job import ManifestJob
from .rows import BatchInterrupted, interrupted_row, unfinished_row
from .worker_pool import WORKER_START

#: what srarap's own Dask workers get instead of Dask's defaults: one BLAS thread, and glibc's
#: dynamic malloc trimming (Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536, which turned each
#: solve's large temporaries into mmap/munmap pairs: system time 0.23 -> 4.5 s for 20 jobs)
WORKER_ENVIRON = {"OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1}
#: Dask settings for the workers srarap starts. They come from a fork server that imported
#: the jobs' code once: a spawned worker imports numpy, scipy, libigl and distributed again
#: (about 1.5 s for two), which made 20 jobs of 5k vertices take 4.7 s against 3.2 s with
#: --workers 2; forked from the batch itself they started at once, but beside the cluster's
#: threads (see :func:`..runtime.threads.worker_processes`). The rest wakes the workers less
#: often:
#: Dask's profiler samples the running task's stack every 10 ms (for a dashboard these
#: clusters do not have), event loops tick every 20 ms, monitors poll psutil 10 times a
#: second; on 2 cores each wake-up takes the core from a solve. With Dask's defaults a job
#: used 5.6% more CPU time in its thread than in a --workers 2 process; with these settings, 1%.
LOCAL_CONFIG = {"distributed.nanny.pre-spawn-environ": WORKER_ENVIRON,
                "distributed.worker.profile.enabled": False,
                "distributed.admin.tick.interval": "1s",
                "distributed.admin.system-monitor.interval": "5s",
                "distributed.worker.memory.monitor-interval": "1s",
                # one task per worker at a time: the death of a worker then counts against
                # the task it ran only (Dask's 1.1 queued a second one there, which failed
                # with it), and a task whose worker died runs once more, then fails (Dask's
                # default, 3 more times, ran a job too large for the machine into its limit
                # 4 times)
                "distributed.scheduler.worker-saturation": 1.0,
                "distributed.scheduler.allowed-failures": 1}


def run_on_dask(jobs: list[ManifestJob], run: "functools.partial[JobResult]", scheduler: str,
                workers: int, unfinished: Callable[[ManifestJob], JobResult] = interrupted_row
                ) -> list[JobResult]:
    """The results of ``jobs`` run by ``run`` (:func:`.batch.run_job` with its keywords
    bound, ``out_dir`` among them) on the cluster at ``scheduler``, or on a local one of
    ``workers`` single-threaded worker processes when ``scheduler`` is ``local``;
    ``unfinished(job)`` is the result of a job a signal stopped."""
    try:
        import dask
        from distributed import LocalCluster
    except ImportError:
        raise InputError("--scheduler needs Dask: pip install 'srarap-cli[dask]'") from None
    run = functools.partial(run, out_dir=hold(run.keywords["out_dir"]))  # absolute, held
    if scheduler != "local":
        return _gather_at(scheduler, jobs, run, scheduler, unfinished)
    # the cluster runs threads from its start: its workers come from a fork server
    with _without_dasks_trim_setting(), \
            worker_processes([WORKER_START, "distributed"], threads_ahead=True) as context:
        with dask.config.set({**LOCAL_CONFIG, "distributed.worker.multiprocessing-method":
                              context.get_start_method()}):
            try:
                # no HTTP port of its own to fight over ("Port 8787 is already in use"),
                # and the workers' log lines only for errors: the summary says what happened
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                       processes=True, dashboard_address=":0",
                                       silence_logs=logging.ERROR)
            except (KeyboardInterrupt, Terminated):
                _silence_dask()  # the half-started cluster's tasks end unattended
                raise
        try:
            return _gather_at(cluster, jobs, run, scheduler, unfinished)
        except _Stopped as stop:
            # the workers end before the disk is read: a task inside its commit when the
            # signal came finishes it or not, and the summary says which (it read the disk
            # while the task still wrote, and called a committed job interrupted)
            block()
            cluster.close()
            raise stop.rows(jobs, unfinished) from None
        finally:
            cluster.close()


def _gather_at(cluster, jobs, run, scheduler, unfinished):
    """The jobs' rows from ``cluster`` (an address or a cluster), which ``--scheduler
    scheduler`` named."""
    from distributed import Client

    try:
        return _gather(Client(cluster, timeout=30), jobs, run)
    except (OSError, TimeoutError) as exc:
        raise InputError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
    except _Stopped as stop:
        if scheduler == "local":
            raise  # its cluster is closed first (run_on_dask)
        raise stop.rows(jobs, unfinished) from None  # a remote cluster's workers go on


class _Stopped(BaseException):
    """A signal stopped the gather: the rows of the tasks that finished (None for the
    others) and the signal's exception."""

    def __init__(self, finished: list[JobResult | None], signal: BaseException) -> None:
        super().__init__("stopped")
        self.finished, self.signal = finished, signal

    def rows(self, jobs: list[ManifestJob],
             unfinished: Callable[[ManifestJob], JobResult]) -> BatchInterrupted:
        return BatchInterrupted([row if row is not None else unfinished(job)
                                 for row, job in zip(self.finished, jobs)], self.signal)


def _without_dasks_trim_setting():
    """A Dask nanny started earlier in this process left its MALLOC_TRIM_THRESHOLD_ in
    ``os.environ``, where new workers would inherit it: hold it back while they spawn."""
    left = os.environ.get("MALLOC_TRIM_THRESHOLD_") == "65536"
    return environ_changed({"MALLOC_TRIM_THRESHOLD_": None} if left else {})


def _silence_dask():
    """Dask's, asyncio's and tornado's log lines while a cluster is stopped early (cancelled
    tasks, lost workers, the interrupted gather's tasks collected later) are not the user's
    concern: the summary says what finished. For the rest of the process, which is ending."""
    import logging
    for name in ("distributed", "asyncio", "tornado"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _gather(client, jobs, run):
    """The rows of ``jobs`` run on ``client``'s cluster. A job Dask gave up on (its worker
    died each time it ran it: Dask's KilledWorker) is a failed row, not the batch's end."""
    with client:
        futures = client.map(run, jobs, pure=False)
        rows = []
        try:
            # one at a time: a finished task whose worker died is computed again, and its
            # result() waits for that
            for future, job in zip(futures, jobs):
                rows.append(_dask_row(future, job))
        except (KeyboardInterrupt, Terminated) as exc:
            _silence_dask()
            finished = [f.result() if f.status == "finished" else None for f in futures]
            client.cancel(futures)
            raise _Stopped(finished, exc) from None
        return rows


def _dask_row(future, job):
    """The job's row from its task; a failed row when the task ended without one
    (``run_job`` itself never raises: its worker died, or the cluster lost it)."""
    import asyncio

    try:
        return future.result()
    except (Exception, asyncio.CancelledError) as exc:
        if type(exc).__name__ == "KilledWorker":
            reason = ("its worker process died each time Dask ran it (the system may have "
                      "run out of memory)")
        else:
            reason = f"Dask: {type(exc).__name__}: {(str(exc).splitlines() or [''])[0][:200]}"
        return unfinished_row(job, reason, 1)
