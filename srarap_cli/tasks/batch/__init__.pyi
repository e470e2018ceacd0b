# The wing's names for type checkers: the package loads them lazily (__init__.py's
# __getattr__). Keep in step with _WHERE there (tests/test_layers.py checks it).
from .manifest import check_goldens as check_goldens
from .manifest import check_outputs as check_outputs
from .manifest import load_manifest as load_manifest
from .on_dask import run_on_dask as run_on_dask
from .rows import BatchInterrupted as BatchInterrupted
from .run import run_batch as run_batch
from .summary import SUMMARIES as SUMMARIES
from .summary import write_reports as write_reports
from .summary import write_summaries as write_summaries
from .worker_pool import run_in_processes as run_in_processes

__all__: list[str]
