"""Logs as CSV or JSON Lines (chosen by the file extension): the per-iteration energy log of
``deform``, the per-frame log of ``animate``, the curves of ``bench``."""
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
