"""Many deformations from one manifest (``srarap batch``): the manifest (``manifest``), the
run with its up-to-date checks (``run``), its workers (``worker_pool``: local processes,
``worker_start``: what their fork server imports; ``on_dask``: a Dask cluster), the rows of
jobs that did not finish (``rows``), and the summary files, report and JUnit it writes
(``summary``; the report and JUnit themselves are shared: ``tasks.reports``).

Names are imported on first use, and nothing here imports ``worker_start``, which changes the
signals of the process that imports it.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
