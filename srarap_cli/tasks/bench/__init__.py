"""``srarap bench``: every method timed on one problem from the same start (``methods``), the
table, curves, summary and plot of the runs (``report``), and the command's job (``job``:
:class:`~.job.BenchJob`, :func:`~.job.run_bench`). Names are imported on first use.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
