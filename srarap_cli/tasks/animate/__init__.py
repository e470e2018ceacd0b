"""An animation (``srarap animate``): the job and its runner (``job``), the frames solved in
sequence with their resume state (``sequence``), the frame files a pattern names
(``frame_files``, which ``render`` reads too).

The entry: a frozen :class:`~.job.AnimateJob`, :func:`~.job.run_animation` and its
:class:`~.job.AnimationOutcome` (``exit_code``, ``warnings``, ``summary()``). Names are imported
on first use.
"""
from ...runtime.lazy_names import lazy_getattr

_WHERE = {"AnimateJob": "job", "run_animation": "job", "AnimationOutcome": "job",
          "Animator": "sequence", "MAX_FRAMES": "frame_files", "frame_paths": "frame_files"}

__all__ = sorted(_WHERE)


__getattr__ = lazy_getattr(__name__, _WHERE)
