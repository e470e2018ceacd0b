"""How far apart two meshes are (``srarap compare``, a job's golden check, the pytest
fixture): the typed :class:`~.compare.Comparison`, the one home of "relative to the diagonal"
(``scaled``) and of a verdict against a tolerance (``verdict``), with the best rigid motion
between corresponding meshes (``align``); the gates of a golden, quantity by quantity
(``gates``: :class:`~.gates.Expect`, :func:`~.gates.judge`); goldens that manage themselves
(``goldens``: their record, their creation and update); the command's job (``job``:
:class:`~.job.CompareJob`, :func:`~.job.run_compare`, :class:`~.job.CompareOutcome`). Names are
imported on first use.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
