"""Why a solve stopped: one value, set where the decision is made (the monitor), read by
every consumer (the summary line, the log's ``stop`` column, a batch's sidecar and summary,
the Python API's ``result.stop_reason``)."""
from enum import StrEnum


class StopReason(StrEnum):
    """How a solve ended. A ``str``, so it prints, compares and serializes as its value.

    ``converged``: the stopping test passed. ``iterations run``: ``tol`` 0 (no stopping
    test) ran the ``max_iter`` iterations asked. ``iteration limit``: ``max_iter`` ran out
    before the test passed. ``time limit``: ``time_limit`` ran out first. ``transfer``: the
    paper's multiresolution transfer, never iterated at full resolution (its coarse solve
    has a reason of its own). ``non-finite``: the energy became NaN or infinite (the solve
    raises :class:`~srarap_cli.runtime.errors.NumericalError`; a batch records the reason).
    ``stopped by driver``: a driver of one's own (``solve(driver=...)``) returned before the
    monitor's tests asked it to.

    Examples
    --------
    >>> StopReason.TIME_LIMIT == "time limit", StopReason("converged").complete
    (True, True)
    """

    CONVERGED = "converged"
    ITERATIONS_RUN = "iterations run"
    ITERATION_LIMIT = "iteration limit"
    TIME_LIMIT = "time limit"
    TRANSFER = "transfer"
    NON_FINITE = "non-finite"
    DRIVER = "stopped by driver"

    @property
    def complete(self) -> bool:
        """Whether the solve ended as asked: converged, or ran the iterations asked."""
        return self in (StopReason.CONVERGED, StopReason.ITERATIONS_RUN)
