"""A batch's jobs in local worker processes: rows in manifest order, a signal stops them all,
and a worker that dies (the out-of-memory killer, a crash in native code) takes only its own
job with it.

When a worker dies, Python's process pool breaks: every job still in it fails with
``BrokenProcessPool`` and the pool takes no more. The pool is therefore given at most one job
per worker at a time, so that the jobs in it when it broke are the only suspects; each is run
again alone in a pool of its own, where the one that kills its worker again is reported failed
with how its worker ended, and the others finish as if nothing had happened. The jobs not yet
started go on in a new pool.
"""
import os
import signal
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from ...runtime import exit_codes
from ...runtime.signals import SIGNALS, Terminated, deferred
from ...runtime.threads import worker_processes

#: what the server that forks worker processes imports first: the jobs' code and the workers'
#: signal dispositions
WORKER_START = "srarap_cli.tasks.batch.worker_start"
#: seconds the workers get to stop after SIGTERM before they are killed
STOP_GRACE = 2.0


class PoolStopped(BaseException):
    """SIGINT or SIGTERM stopped the pool: ``rows`` maps the finished jobs' positions to their
    rows; ``signal`` is the exception the signal raised."""

    def __init__(self, rows: dict[int, Any], signal: BaseException) -> None:
        super().__init__("stopped")
        self.rows, self.signal = rows, signal


def run_in_processes(jobs: Sequence[Any], run: Callable[[Any], Any], workers: int,
                     lost: Callable[[Any, int], Any]) -> list[Any]:
    """``run(job)`` for every job in ``workers`` processes; the rows in the jobs' order.

    Parameters
    ----------
    jobs : sequence of picklable jobs
    run : picklable callable(job) -> row, which never raises
    workers : int >= 1
    lost : callable(job, exitcode) -> row, the row of a job whose worker died when it ran
        alone (``exitcode``: the process's, negative for a signal)

    Raises
    ------
    PoolStopped : a SIGINT or SIGTERM came; the workers are stopped (SIGTERM, then SIGKILL
        after :data:`STOP_GRACE` seconds)
    """
    rows: dict[int, Any] = {}
    with worker_processes([WORKER_START]) as context:
        waiting = list(range(len(jobs)))
        while waiting:
            suspects, _ = _run_pool(context, workers, jobs, run, waiting, rows)
            for k in suspects:  # alone: a job whose worker dies again is the one that kills it
                again, exitcode = _run_pool(context, 1, jobs, run, [k], rows)
                if again:
                    rows[k] = lost(jobs[k], exitcode)
            waiting = [k for k in waiting if k not in rows]
    return [rows[k] for k in range(len(jobs))]


def death_note(exitcode: int) -> str:
    """How a worker process ended, for a job's message: ``exitcode`` as
    ``multiprocessing.Process.exitcode`` gives it (negative: the signal that killed it).

    Examples
    --------
    >>> death_note(-9)
    'its worker process was killed by SIGKILL (the system may have run out of memory)'
    >>> death_note(3)
    'its worker process exited with code 3'
    """
    if exitcode >= 0:
        return f"its worker process exited with code {exitcode}"
    try:
        name = signal.Signals(-exitcode).name
    except ValueError:
        name = f"signal {-exitcode}"
    hint = " (the system may have run out of memory)" if -exitcode == signal.SIGKILL else ""
    return f"its worker process was killed by {name}{hint}"


def _run_pool(context, workers, jobs, run, ids, rows):
    """Run the jobs ``ids`` not in ``rows`` yet in one pool, adding their rows to ``rows``,
    until done or until a worker dies. Returns the jobs that were in the pool when it broke
    (empty if it did not) and the dead worker's exit code (0 if none is known)."""
    forked = context.get_start_method() == "fork"
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context,
                               initializer=_worker_signals,
                               initargs=(os.getpid() if forked else None,))
    queue = iter([k for k in ids if k not in rows])
    running: dict[Any, int] = {}
    broken: list[int] = []
    processes: list[Any] = []
    try:
        _top_up(pool, queue, running, workers, jobs, run, processes)
        while running:
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                k = running.pop(future)
                try:
                    rows[k] = future.result()
                except BrokenProcessPool:
                    broken.append(k)
            if not broken:
                _top_up(pool, queue, running, workers, jobs, run, processes)
        pool.shutdown()
        return sorted(broken), _dead_exitcode(processes) if broken else 0
    except (KeyboardInterrupt, Terminated) as exc:
        _stop(pool)
        raise PoolStopped(rows, exc) from None


def _top_up(pool, queue, running, workers, jobs, run, processes):
    """Give the pool jobs until each worker has one. Workers start on a submit, with
    SIGINT/SIGTERM held back until their initializer has taken them: a Ctrl-C that reached a
    worker just forked, still with this process's handlers, raised in its start-up."""
    with deferred():
        while len(running) < workers and (k := next(queue, None)) is not None:
            running[pool.submit(run, jobs[k])] = k
    processes.extend(p for p in getattr(pool, "_processes", {}).values() if p not in processes)


def _dead_exitcode(processes):
    """The exit code of the worker that broke the pool: the one that did not end by the
    pool's own SIGTERM to the others (0 if none is known)."""
    codes = []
    for p in processes:
        p.join(STOP_GRACE)
        if p.exitcode is not None:
            codes.append(p.exitcode)
    dead = [c for c in codes if c not in (0, -signal.SIGTERM, exit_codes.TERMINATED)]
    return dead[0] if dead else (codes[0] if codes else 0)


def _worker_signals(batch_pid=None):
    """A worker leaves SIGINT to the batch (a terminal's Ctrl-C reaches the whole group: the
    batch stops the workers and reports) and leaves at once on SIGTERM, from the batch: an
    exception raised there could land in any destructor and print a traceback. Its commits
    hold signals back while they rename, and the temporary files it staged are swept by
    the next write into their folder. It never outlives its parent (the batch, or the fork
    server that ends with it): see :func:`_die_with`."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, lambda signum, frame: os._exit(exit_codes.TERMINATED))
    signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)  # held back since the fork
    _die_with(batch_pid)


def _die_with(batch_pid):
    """Have the kernel kill this worker when its parent ends (Linux), and leave now if the
    batch (``batch_pid``, the parent of a forked worker) already has. A worker forked just
    as a signal stopped the batch, before the batch knew of it, escaped the batch's
    SIGTERM/SIGKILL: it then waited for a job forever, and held the batch's standard error
    open (a CI test waiting for its end timed out)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the batch's own stop has to do
        pass
    if batch_pid is not None and os.getppid() != batch_pid:
        os._exit(exit_codes.TERMINATED)


def _stop(pool):
    processes = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        if p.is_alive():
            p.terminate()
    deadline = time.monotonic() + STOP_GRACE
    for p in processes:
        p.join(max(deadline - time.monotonic(), 0.0))
        if p.is_alive():
            p.kill()
            p.join(1.0)
    _let_exit_go(pool)


def _let_exit_go(pool):
    """Keep the interpreter's exit from waiting on the pool's threads once its workers are
    gone. At exit Python joins the executor's manager thread and the call queue's feeder
    thread without a timeout; with the workers killed mid-job, under load, one of them could
    still be waiting (a batch stopped by a signal took 39 s, once more than 60, to end after
    its summary was written). Both are given the grace period, then left behind."""
    from concurrent.futures import process

    queue = getattr(pool, "_call_queue", None)
    if queue is not None:
        queue.cancel_join_thread()
    thread = getattr(pool, "_executor_manager_thread", None)
    if thread is not None:
        thread.join(STOP_GRACE)
        if thread.is_alive():
            getattr(process, "_threads_wakeups", {}).pop(thread, None)
