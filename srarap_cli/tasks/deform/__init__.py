"""One deformation as a command runs it (``srarap deform``, a batch job): the job and its
runner with the up-to-date check (``job``), its record beside the output (``record``), the
check against a golden mesh (``golden``) and what the summary line says (``advice``).

The entry: a frozen :class:`~.job.DeformJob`, :func:`~.job.run_job`, and its outcome, a
:class:`~srarap_cli.tasks.job_status.JobResult` (exit code, warnings). Other wings reach it
through this package; names are imported on first use.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
