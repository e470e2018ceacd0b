"""Many deformations from one manifest (``srarap batch``): the manifest (``manifest``), the
run with its up-to-date checks (``run``), its workers (``worker_pool``: local processes,
``worker_start``: what their fork server imports; ``on_dask``: a Dask cluster), the rows of
jobs that did not finish (``rows``), and the summary files, report and JUnit it writes
(``summary``; the report and JUnit themselves are shared: ``tasks.reports``).

Names are imported on first use, and nothing here imports ``worker_start``, which changes the
signals of the process that imports it.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"run_batch": "run", "BatchInterrupted": "rows", "load_manifest": "manifest",
          "check_outputs": "manifest", "check_goldens": "manifest",
          "write_summaries": "summary", "write_reports": "summary",
          "run_on_dask": "on_dask", "run_in_processes": "worker_pool", "SUMMARIES": "summary"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
