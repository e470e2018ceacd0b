"""How far apart two meshes are (``srarap compare``, a job's golden check): the typed
:class:`~.compare.Comparison`, the one home of "relative to the diagonal" (``scaled``) and of a
verdict against a tolerance (``verdict``); the command's job (``job``: :class:`~.job.CompareJob`,
:func:`~.job.run_compare`, :class:`~.job.CompareOutcome`). Names are imported on first use.
"""
import importlib
from typing import Any

_WHERE = {"Comparison": "compare", "Verdict": "compare", "compare_meshes": "compare",
          "CompareJob": "job", "CompareOutcome": "job", "run_compare": "job"}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
