"""How far apart two meshes are (``srarap compare``, a job's golden check, the pytest
fixture): the typed :class:`~.compare.Comparison`, the one home of "relative to the diagonal"
(``scaled``) and of a verdict against a tolerance (``verdict``), with the best rigid motion
between corresponding meshes (``align``); the gates of a golden, quantity by quantity
(``gates``: :class:`~.gates.Expect`, :func:`~.gates.judge`); goldens that manage themselves
(``goldens``: their record, their creation and update); the command's job (``job``:
:class:`~.job.CompareJob`, :func:`~.job.run_compare`, :class:`~.job.CompareOutcome`). Names are
imported on first use.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"Comparison": "compare", "Verdict": "compare", "compare_meshes": "compare",
          "CompareJob": "job", "CompareOutcome": "job", "run_compare": "job",
          "Expect": "gates", "Observed": "gates", "judge": "gates", "parse_expect": "gates",
          "verdict_line": "gates",
          "EXPECT_KEYS": "gates", "GATE_KEYS": "gates", "read_golden_record": "goldens",
          "write_golden": "goldens", "refuse_leading_out": "goldens", "record_path": "goldens"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
