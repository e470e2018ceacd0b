"""The checks a task's frozen job makes of its own fields when it is built, so that a Python
caller gets one ValueError or TypeError naming the field (as ``deform`` checks its
arguments), never a KeyError, ZeroDivisionError or OverflowError from deep inside a run."""
import math
import os
from collections.abc import Sequence
from typing import Any


def text(job: Any, name: str, optional: bool = False) -> None:
    """``job.<name>`` is a path or text (or None where ``optional``)."""
    value = getattr(job, name)
    if value is None and optional:
        return
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{type(job).__name__}.{name} must be text (a str or a path), got "
                        f"{type(value).__name__}")


def choice(job: Any, name: str, choices: Sequence[str]) -> None:
    """``job.<name>`` is one of ``choices``."""
    value = getattr(job, name)
    if value not in choices:
        raise ValueError(f"{type(job).__name__}.{name} must be one of {', '.join(choices)}, "
                         f"got {value!r}")


def number(job: Any, name: str, low: float = 0.0, high: float = math.inf,
           optional: bool = False, low_open: bool = False) -> None:
    """``job.<name>`` is a finite number in ``[low, high]`` (``(low, high]`` with
    ``low_open``), or None where ``optional``."""
    value = getattr(job, name)
    if value is None and optional:
        return
    try:
        good = (not isinstance(value, bool) and isinstance(value, (int, float))
                and math.isfinite(value) and (value > low if low_open else value >= low)
                and value <= high)
    except OverflowError:  # an integer past a float's range
        good = False
    if not good:
        bounds = f"{'>' if low_open else '>='} {low:g}" + (f" and <= {high:g}"
                                                           if high < math.inf else "")
        raise ValueError(f"{type(job).__name__}.{name} must be a finite number {bounds}, got "
                         f"{str(value)[:40]}")


def count(job: Any, name: str, optional: bool = False) -> None:
    """``job.<name>`` is a whole number of at least 1 (or None where ``optional``)."""
    value = getattr(job, name)
    if value is None and optional:
        return
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{type(job).__name__}.{name} must be a whole number >= 1, got "
                         f"{str(value)[:40]}")


def texts(job: Any, name: str) -> None:
    """``job.<name>`` is a non-empty tuple or list of text."""
    value = getattr(job, name)
    if isinstance(value, str) or not isinstance(value, (tuple, list)) or not value \
            or not all(isinstance(v, (str, os.PathLike)) for v in value):
        raise ValueError(f"{type(job).__name__}.{name} must be a non-empty tuple of text, got "
                         f"{str(value)[:40]}")


def flag(job: Any, name: str) -> None:
    """``job.<name>`` is True or False."""
    if not isinstance(getattr(job, name), bool):
        raise TypeError(f"{type(job).__name__}.{name} must be True or False")


def of_type(job: Any, cls: type, run: str) -> None:
    """``job`` is a ``cls`` (a dict or another job is a TypeError naming ``run``)."""
    if not isinstance(job, cls):
        raise TypeError(f"{run} takes a {cls.__name__}, got {type(job).__name__}")
