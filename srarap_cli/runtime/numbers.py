"""Numbers as YAML and JSON spell them. YAML 1.1 (PyYAML's) reads ``9e1`` and ``5e-1``, an
exponent without a dot, as text; a handle file, a manifest and a setting take them as the
numbers they spell, the same in a scalar as in a vector."""
import re
from typing import Any

#: a decimal number, with an optional fraction, exponent and YAML's ``_`` digit separators
NUMBER = re.compile(r"[-+]?(\d[\d_]*\.?\d*|\.\d+)([eE][-+]?\d+)?")


def spelled(value: Any) -> Any:
    """``value``, or the float a text spells when it is a number.

    Examples
    --------
    >>> spelled("9e1"), spelled("-5e-1"), spelled("1_000"), spelled("nine"), spelled(3)
    (90.0, -0.5, 1000.0, 'nine', 3)
    """
    if isinstance(value, str) and NUMBER.fullmatch(value.strip()):
        return float(value.replace("_", ""))
    return value


def whole(value: Any) -> Any:
    """``value`` as an int when it is a float with no fraction (``1e3``: 1000), else as is.

    Examples
    --------
    >>> whole(1e3), whole(2.5), whole(True)
    (1000, 2.5, True)
    """
    if isinstance(value, float) and value.is_integer() and abs(value) <= 2 ** 53:
        return int(value)
    return value


#: a whole number of more digits than this is beyond any count srarap takes (threads,
#: vertices): read as this, so that a count is capped as any large one, where Python's
#: ``int`` would refuse past 4300 digits
HUGE = 10 ** 18


def digits_value(text: str) -> int:
    """The int an ASCII digit string spells, at most :data:`HUGE`.

    Examples
    --------
    >>> digits_value("0012"), digits_value("9" * 5000) == HUGE
    (12, True)
    """
    text = text.lstrip("0") or "0"
    return int(text) if len(text) <= 18 else HUGE
