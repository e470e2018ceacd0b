"""An animation (``srarap animate``): the job and its runner (``job``), the frames solved in
sequence with their resume state (``sequence``), the frame files a pattern names
(``frame_files``, which ``render`` reads too).

The entry: a frozen :class:`~.job.AnimateJob`, :func:`~.job.run_animation` and its
:class:`~.job.AnimationOutcome` (``exit_code``, ``warnings``, ``summary()``). Names are imported
on first use.
"""
import importlib
from typing import Any

_WHERE = {"AnimateJob": "job", "run_animation": "job", "AnimationOutcome": "job",
          "Animator": "sequence", "MAX_FRAMES": "frame_files", "frame_paths": "frame_files"}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
