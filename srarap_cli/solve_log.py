"""The per-iteration energy log, as CSV or JSON Lines (chosen by the file extension)."""
import io
import json
import math

from .deformer import LOG_FIELDS

LOG_FORMATS = (".csv", ".jsonl", ".ndjson")


def format_log(rows, suffix):
    """Log text for ``rows`` (dicts with LOG_FIELDS); numbers written with full precision."""
    buf = io.StringIO()
    if suffix == ".csv":
        buf.write(",".join(LOG_FIELDS) + "\n")
        for row in rows:
            buf.write(",".join(_cell(row[k]) for k in LOG_FIELDS) + "\n")
    else:
        for row in rows:
            buf.write(json.dumps({k: _json(row[k]) for k in LOG_FIELDS}) + "\n")
    return buf.getvalue()


def _cell(value):
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return str(value)


def _json(value):
    return None if isinstance(value, float) and math.isnan(value) else value
