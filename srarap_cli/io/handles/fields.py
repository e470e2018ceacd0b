"""Typed field access for the handle file, with errors that name file, group and field."""
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from ...runtime.errors import InputError, unknown_key
from ...runtime.numbers import spelled, whole
from ...runtime.warning_codes import note

#: Largest integer a handle file may hold (vertex ids and counts fit in int64 with room).
MAX_INT = 2 ** 53


def _numeric(value: Any) -> Any:
    """``value`` with every number spelled as text made a float; raises TypeError for
    anything else that is not a number (text, a truth value, null, a mapping)."""
    if isinstance(value, (list, tuple)):
        return [_numeric(v) for v in value]
    value = spelled(value)
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"not a number: {type(value).__name__}")
    return value


class Context:
    """Where a value sits in the handle file, for one-line error messages and warnings.

    Attributes
    ----------
    warnings : list of str, shared by every Context made with :meth:`at`: what was accepted
        but looks like a mistake (see :meth:`warn`)
    """

    def __init__(self, path: str, where: str = "", warnings: list[str] | None = None) -> None:
        self.path = path
        self.where = where
        self.warnings = [] if warnings is None else warnings

    def at(self, where: str) -> "Context":
        return Context(self.path, where, self.warnings)

    def _prefixed(self, message):
        return (f"{self.path}: {self.where}: " if self.where else f"{self.path}: ") + message

    def error(self, message: str) -> InputError:
        return InputError(self._prefixed(message))

    def warn(self, code: str, message: str) -> None:
        """Record a warning (its ``code``, one of :data:`~srarap_cli.runtime.warning_codes.CODES`)
        naming the file and where in it (``--strict`` makes it an error)."""
        self.warnings.append(note(code, self._prefixed(message)))

    def mapping(self, value: Any, name: str, allowed: Iterable[str]) -> dict:
        if not isinstance(value, dict):
            raise self.error(f"{name} must be a mapping of keys to values")
        unknown = sorted(set(map(str, value)) - set(allowed))
        if unknown:
            raise self.error(unknown_key(unknown[0], allowed, name))
        return value

    def record(self, value: Any, name: str, keys: Sequence[str]) -> dict:
        """A mapping with exactly ``keys``, all of them required."""
        value = self.mapping(value, name, keys)
        missing = [k for k in keys if k not in value]
        if missing:
            raise self.error(f"{name} needs " + " and ".join(f"{k!r}" for k in keys))
        return value

    def vector(self, value: Any, name: str, length: int) -> np.ndarray:
        arr = self.numbers(value, name)
        if arr.shape != (length,):
            raise self.error(f"{name} must be a list of {length} numbers")
        return arr

    def matrix4(self, value: Any, name: str) -> np.ndarray:
        arr = self.numbers(value, name)
        if arr.size == 16:
            arr = arr.reshape(4, 4)
        if arr.shape != (4, 4):
            raise self.error(f"{name} must be a 4x4 matrix (4 rows of 4 numbers)")
        return arr

    def numbers(self, value: Any, name: str) -> np.ndarray:
        """``value`` (a number, or nested lists of numbers) as a float array. A number is
        any YAML or JSON number: YAML 1.1 reads ``9e1`` (an exponent without a dot) as text,
        which is taken as the number it spells, in a scalar as in a vector."""
        try:
            arr = np.asarray(_numeric(value), dtype=float)
        except (TypeError, ValueError):
            raise self.error(f"{name} must be numeric") from None
        except OverflowError:
            raise self.error(f"{name} must be finite (a number beyond the float range)") \
                from None
        if not np.isfinite(arr).all():
            raise self.error(f"{name} must be finite")
        return arr

    def number(self, value: Any, name: str, minimum: float | None = None,
               strict: bool = False) -> float:
        arr = self.numbers(value, name)
        if arr.ndim != 0:
            raise self.error(f"{name} must be a single number")
        x = float(arr)
        if minimum is not None and (x <= minimum if strict else x < minimum):
            raise self.error(f"{name} must be {'>' if strict else '>='} {minimum:g}")
        return x

    def integer(self, value: Any, name: str, minimum: int | None = None) -> int:
        """``value`` as an int: an integer, or a number with no fraction (``5e0``, ``5.0``)."""
        value = spelled(value)
        if isinstance(value, (float, np.floating)):
            value = whole(float(value))
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise self.error(f"{name} must be an integer")
        if minimum is not None and value < minimum:
            raise self.error(f"{name} must be >= {minimum}")
        if abs(int(value)) > MAX_INT:
            raise self.error(f"{name}: {int(value)} is out of range")
        return int(value)
