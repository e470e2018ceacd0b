# The wing's names for type checkers: the package loads them lazily (__init__.py's
# __getattr__). Keep in step with _WHERE there (tests/test_layers.py checks it).
from .advice import cache_hint as cache_hint
from .advice import summary_line as summary_line
from .golden import check_golden as check_golden
from .job import DeformJob as DeformJob
from .job import JobResult as JobResult
from .job import JobStatus as JobStatus
from .job import recorded_result as recorded_result
from .job import run_job as run_job
from .job import run_job_safely as run_job_safely
from .record import fingerprint as fingerprint
from .record import sidecar_path as sidecar_path

__all__: list[str]
