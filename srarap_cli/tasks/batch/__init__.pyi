# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from .job import BatchJob as BatchJob
from .job import BatchOutcome as BatchOutcome
from .job import run_batch as run_batch
from .manifest import SUMMARIES as SUMMARIES
from .manifest import check_goldens as check_goldens
from .manifest import check_outputs as check_outputs
from .manifest import load_manifest as load_manifest
from .manifest_job import ManifestJob as ManifestJob
from .on_dask import run_on_dask as run_on_dask
from .rows import BatchInterrupted as BatchInterrupted
from .run import run_jobs as run_jobs
from .summary import write_reports as write_reports
from .summary import write_summaries as write_summaries
from .worker_pool import run_in_processes as run_in_processes

__all__: list[str]
