"""A batch's summary rows: their fields, the rows of jobs that did not finish (a signal stopped
the batch, a worker process died), and the interruption that carries them."""
from typing import Any

from .report import EXIT_CODES
from .worker_pool import death_note

#: a job of a manifest: name, absolute paths, output, settings, expect
Job = dict[str, Any]
#: a job's summary row (keys SUMMARY_FIELDS)
Row = dict[str, Any]
#: ``stop``: the solve's :class:`~srarap_cli.solver.stop.StopReason` (empty for a job that
#: never reached the solver)
SUMMARY_FIELDS = ("job", "status", "stop", "iterations", "energy", "seconds", "compare_max",
                  "message", "compare_mean", "tol", "exit_code")


class BatchInterrupted(BaseException):
    """SIGINT or SIGTERM stopped a batch: ``rows`` are the summary rows, in manifest order,
    of the jobs that finished and of the others (``status`` ``interrupted``); ``signal`` the
    exception the signal raised."""

    def __init__(self, rows: list[Row], signal: BaseException) -> None:
        super().__init__("interrupted")
        self.rows, self.signal = rows, signal


def interrupted_row(job: Job) -> Row:
    """The summary row of a job a signal stopped before it finished."""
    return {"job": job["name"], "status": "interrupted", "stop": "", "iterations": None,
            "energy": None, "seconds": None, "compare_max": None,
            "message": "not finished: the batch was interrupted", "compare_mean": None,
            "tol": None, "exit_code": EXIT_CODES["interrupted"]}


def lost_row(job: Job, exitcode: int) -> Row:
    """The summary row of a job whose worker process died when it ran alone."""
    return unfinished_row(job, death_note(exitcode),
                           128 - exitcode if exitcode < 0 else exitcode or 1)


def unfinished_row(job: Job, reason: str, exit_code: int) -> Row:
    """The summary row of a job that failed without a row of its own (its process died)."""
    return {**interrupted_row(job), "status": "failed", "exit_code": exit_code,
            "message": f"not finished: {reason}"}
