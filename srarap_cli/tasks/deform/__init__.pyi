# The wing's names, the only list of them: type checkers read it, and the package's
# __init__.py loads each name from the module named here on first use (attach_stub).
from ..job_status import JobResult as JobResult
from ..job_status import JobStatus as JobStatus
from .advice import cache_hint as cache_hint
from .advice import summary_line as summary_line
from .golden import check_golden as check_golden
from .job import DeformJob as DeformJob
from .job import recorded_result as recorded_result
from .job import run_job as run_job
from .job import run_job_safely as run_job_safely
from .record import sidecar_path as sidecar_path

__all__: list[str]
