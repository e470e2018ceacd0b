"""How far apart two meshes are (``srarap compare``, a job's golden check): the typed
:class:`~.compare.Comparison`, the one home of "relative to the diagonal" (``scaled``) and of a
verdict against a tolerance (``verdict``); the command's job (``job``: :class:`~.job.CompareJob`,
:func:`~.job.run_compare`, :class:`~.job.CompareOutcome`). Names are imported on first use.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"Comparison": "compare", "Verdict": "compare", "compare_meshes": "compare",
          "CompareJob": "job", "CompareOutcome": "job", "run_compare": "job"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
