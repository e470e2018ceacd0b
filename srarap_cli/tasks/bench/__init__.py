"""``srarap bench``: every method timed on one problem from the same start (``methods``), the
table, curves, summary and plot of the runs (``report``), and the command's job (``job``:
:class:`~.job.BenchJob`, :func:`~.job.run_bench`). Names are imported on first use.
"""
import importlib
from typing import Any

_WHERE = {"BenchJob": "job", "run_bench": "job", "CHOICES": "job", "OWN_DEFAULTS": "job",
          "run_methods": "methods", "ALL_METHODS": "methods", "table": "report"}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
