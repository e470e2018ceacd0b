"""Logs as CSV or JSON Lines (chosen by the file extension): the per-iteration energy log of
``deform``, the per-frame log of ``animate``, the curves of ``bench``."""
import csv
import io
import json
import math
from typing import Any

LOG_FORMATS = (".csv", ".jsonl", ".ndjson")
#: ``stop``: empty but on the row where a solve (or a multiresolution level) stopped, which
#: holds why (:class:`srarap_cli.solver.stop.StopReason`'s value)
LOG_FIELDS = ("iteration", "membrane", "bending", "total", "rel_change", "max_move", "seconds",
              "step", "stop")


def format_log(rows: list[dict[str, Any]], suffix: str,
               fields: tuple[str, ...] = LOG_FIELDS) -> str:
    """Log text for ``rows`` (dicts with ``fields``); numbers with full precision, NaN as an
    empty cell (null in JSON), booleans as ``true``/``false``.

    Examples
    --------
    >>> print(format_log([{"a": 1.5, "b": True}], ".csv", ("a", "b")), end="")
    a,b
    1.5,true
    """
    buf = io.StringIO()
    if suffix == ".csv":
        buf.write(",".join(fields) + "\n")
        for row in rows:
            buf.write(",".join(_cell(row[k]) for k in fields) + "\n")
    else:
        for row in rows:
            buf.write(json.dumps({k: _json(row[k]) for k in fields}) + "\n")
    return buf.getvalue()


def _cell(value):
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return str(value)


def _json(value):
    return None if isinstance(value, float) and math.isnan(value) else value


#: what every row of a log has, for reading it back (``srarap plot``)
READ_FIELDS = ("iteration", "total", "seconds")


def read_log(path: str) -> list[dict[str, Any]]:
    """The rows of a log :func:`format_log` wrote (CSV or JSON lines, by ``path``'s
    extension), each with finite ``iteration``, ``total`` and ``seconds``; InputError naming
    the file, and the row, for anything else."""
    from ..runtime.errors import InputError
    from .input_files import open_input
    try:
        with open_input(path, encoding="utf-8") as fh:
            if path.lower().endswith(".csv"):
                rows = list(csv.DictReader(fh))
            else:
                rows = [json.loads(line) for line in fh if line.strip()]
    except RecursionError:  # json nests as deep as the text does: a hostile line
        raise InputError(f"{path}: not a readable log (a row nested too deeply)") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a readable log ({exc})") from None
    if not rows or not all(isinstance(r, dict) and set(READ_FIELDS) <= set(r) for r in rows):
        raise InputError(f"{path}: not a srarap deform log (every row needs iteration, total, "
                         "seconds)")
    for k, row in enumerate(rows):
        bad = next((f for f in READ_FIELDS if not _finite(row[f])), None)
        if bad is not None:
            raise InputError(f"{path}: row {k + 1}: {bad} is not a number")
    return rows


def _finite(value):
    try:
        return math.isfinite(float(value))
    except (TypeError, ValueError, OverflowError):
        return False
