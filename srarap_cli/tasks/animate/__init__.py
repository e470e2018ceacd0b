"""An animation (``srarap animate``): the job and its runner (``job``), the frames solved in
sequence with their resume state (``sequence``), the frame files a pattern names
(``frame_files``, which ``render`` reads too).

The entry: a frozen :class:`~.job.AnimateJob`, :func:`~.job.run_animation` and its
:class:`~.job.AnimationOutcome` (``exit_code``, ``warnings``, ``summary()``). Names are imported
on first use.
"""
from ...runtime.lazy_names import attach_stub

__getattr__, __dir__, __all__ = attach_stub(__name__, __file__)
