"""One deformation as a command runs it (``srarap deform``, a batch job): the job and its
runner with the up-to-date check (``job``), its record beside the output (``record``), the
check against a golden mesh (``golden``) and what the summary line says (``advice``).

The entry: a frozen :class:`~.job.DeformJob`, :func:`~.job.run_job`, and its outcome, a
:class:`~srarap_cli.tasks.job_status.JobResult` (exit code, warnings). Other wings reach it
through this package; names are imported on first use.
"""
import importlib
from typing import Any

_WHERE = {"DeformJob": "job", "run_job": "job", "run_job_safely": "job", "recorded_result": "job",
          "check_golden": "golden", "summary_line": "advice", "cache_hint": "advice",
          "fingerprint": "record", "sidecar_path": "record", "JobStatus": "job",
          "JobResult": "job"}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
