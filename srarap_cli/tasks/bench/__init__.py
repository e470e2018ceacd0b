"""``srarap bench``: every method timed on one problem from the same start (``methods``), the
table, curves, summary and plot of the runs (``report``), and the command's job (``job``:
:class:`~.job.BenchJob`, :func:`~.job.run_bench`). Names are imported on first use.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"BenchJob": "job", "run_bench": "job", "CHOICES": "job", "OWN_DEFAULTS": "job",
          "run_methods": "methods", "ALL_METHODS": "methods", "table": "report"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
