"""What a batch did, for people and for CI systems: one self-contained HTML page (pictures
embedded, no script, nothing fetched) and JUnit XML.

Both are pure functions of the summary rows (and the pictures the workers drew), with no
timestamp or random id: two runs on identical inputs differ only in the seconds measured.
"""
import base64
import html
import math
from collections.abc import Sequence
from typing import Any
from xml.sax.saxutils import quoteattr

#: the order jobs are shown in: what needs a look first
ATTENTION = ("failed", "regressed", "not-converged", "interrupted", "ok", "up-to-date")
#: a batch status -> the exit code ``srarap deform`` / ``compare`` gives for the same outcome
EXIT_CODES = {"ok": 0, "up-to-date": 0, "not-converged": 3, "regressed": 7,
              "interrupted": 130}
COLOURS = {"failed": "#c62828", "regressed": "#c62828", "not-converged": "#ef6c00",
           "interrupted": "#6d4c41", "ok": "#2e7d32", "up-to-date": "#558b2f"}
PICTURES = (("shape", "rest (ghosted) and result, handles coloured"),
            ("difference", "distance to the golden mesh"),
            ("energy", "energy per iteration"))

STYLE = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 24px; color: #222; max-width: 1200px; }
h1 { font-size: 22px; margin: 0 0 4px; }
.summary { background: #f5f5f5; padding: 10px 14px; border-radius: 6px; margin: 12px 0 20px; }
.job { border: 1px solid #ddd; border-radius: 6px; padding: 10px 14px; margin: 0 0 14px; }
.job h2 { font-size: 16px; margin: 0 0 6px; }
.badge { color: #fff; border-radius: 4px; padding: 1px 8px; font-size: 12px; }
table { border-collapse: collapse; margin: 4px 0 8px; }
td, th { text-align: left; padding: 1px 14px 1px 0; font-size: 13px; }
th { font-weight: 600; color: #555; font-size: 12px; }
figure { display: inline-block; margin: 0 10px 0 0; vertical-align: top; }
figcaption { font-size: 11px; color: #555; max-width: 240px; }
.message { font-family: monospace; white-space: pre-wrap; }
"""


def exit_code(row: dict[str, Any]) -> int | None:
    """The job's outcome as an exit code (a failed job's from its row: 4 input, 5
    numerical, 6 output, 1 otherwise)."""
    if row["status"] == "failed":
        return row.get("exit_code") or 1
    return EXIT_CODES.get(row["status"])


def ordered(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows in the order a reviewer needs them: failures and regressions first (manifest
    order within each status)."""
    rank = {s: k for k, s in enumerate(ATTENTION)}
    return sorted(rows, key=lambda r: rank.get(r["status"], len(rank)))


def _number(value, fmt):
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else format(value, fmt)


def _seconds(value, fmt=".2f"):
    """Measured seconds, marked: the only text two reports of identical inputs differ in."""
    return f"<span class=\"seconds\">{_number(value, fmt)}</span>"


def _summary(rows):
    counts = {s: sum(r["status"] == s for r in rows) for s in ATTENTION}
    parts = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    seconds = sum(r["seconds"] or 0.0 for r in rows)
    compared = [r for r in rows if r.get("compare_max") is not None]
    worst = max(compared, key=lambda r: r["compare_max"], default=None)
    far = (f"; the largest distance to a golden mesh: {worst['compare_max']:.3g} "
           f"({html.escape(worst['job'])})" if worst else "")
    return (f"<p class=\"summary\"><b>{len(rows)} jobs</b>: {parts}; "
            f"{_seconds(seconds, '.1f')} s of solving{far}</p>")


def _job(row, pictures):
    status = row["status"]
    numbers = [("exit code", _number(exit_code(row), "d")),
               ("stop", row.get("stop") or "-"),
               ("iterations", _number(row.get("iterations"), "d")),
               ("seconds", _seconds(row.get("seconds"))),
               ("energy", _number(row.get("energy"), ".6g")),
               ("to golden: max", _number(row.get("compare_max"), ".3g")),
               ("mean", _number(row.get("compare_mean"), ".3g")),
               ("tolerance", _number(row.get("tol"), "g"))]
    table = ("<tr>" + "".join(f"<th>{k}</th>" for k, _ in numbers) + "</tr><tr>"
             + "".join(f"<td>{v}</td>" for _, v in numbers) + "</tr>")
    figures = "".join(
        f"<figure><img alt=\"{html.escape(caption)}\" src=\"data:image/png;base64,"
        f"{pictures[key]}\"><figcaption>{html.escape(caption)}</figcaption></figure>"
        for key, caption in PICTURES if key in pictures)
    message = "".join(f"<p class=\"message\">{html.escape(text)}</p>"
                      for text in (row.get("message"), pictures.get("note")) if text)
    return (f"<section class=\"job\" id=\"{html.escape(row['job'], quote=True)}\"><h2>"
            f"{html.escape(row['job'])} <span class=\"badge\" style=\"background:"
            f"{COLOURS.get(status, '#555')}\">{html.escape(status)}</span></h2>{message}"
            f"<table>{table}</table>{figures}</section>")


def report_html(rows: Sequence[dict[str, Any]], pictures: dict[str, dict[str, str]],
                title: str) -> str:
    """The batch report: a summary, then one section per job, those needing a look first.

    Parameters
    ----------
    rows : list of dict, summary rows (``SUMMARY_FIELDS``)
    pictures : dict job name -> dict picture name (``shape``, ``difference``, ``energy``) ->
        base64 PNG
    title : str, the page's heading (the manifest's name)
    """
    jobs = "".join(_job(r, pictures.get(r["job"], {})) for r in ordered(rows))
    return ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>"
            f"<h1>{html.escape(title)}</h1>{_summary(rows)}{jobs}</body></html>\n")


def encode_png(data: bytes) -> str:
    """PNG bytes as the base64 text an ``<img src="data:...">`` holds."""
    return base64.b64encode(data).decode("ascii")


def junit_xml(rows: Sequence[dict[str, Any]], suite: str) -> str:
    """JUnit XML of a batch: one test case per job (class name ``srarap.<suite>``). A failed
    job is an ``error``; a regressed or unconverged one a ``failure``; an up-to-date one
    ``skipped`` (not solved in this run: its recorded result stands); the message line and
    the distances in each."""
    cases, failures, errors, skipped = [], 0, 0, 0
    for r in rows:
        status = r["status"]
        detail = _detail(r)
        inner = ""
        if status in ("failed", "interrupted"):
            errors += 1
            inner = f"<error type={quoteattr(status)} message={quoteattr(detail)}/>"
        elif status in ("regressed", "not-converged"):
            failures += 1
            inner = f"<failure type={quoteattr(status)} message={quoteattr(detail)}/>"
        elif status == "up-to-date":
            skipped += 1
            inner = f"<skipped message={quoteattr(detail)}/>"
        cases.append(f"    <testcase name={quoteattr(r['job'])} "
                     f"classname={quoteattr('srarap.' + suite)} "
                     f"time=\"{(r['seconds'] or 0.0):.3f}\">{inner}</testcase>")
    seconds = sum(r["seconds"] or 0.0 for r in rows)
    head = (f"tests=\"{len(rows)}\" failures=\"{failures}\" errors=\"{errors}\" "
            f"time=\"{seconds:.3f}\"")
    return ("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            f"<testsuites name={quoteattr(suite)} {head}>\n"
            f"  <testsuite name={quoteattr(suite)} {head} skipped=\"{skipped}\">\n"
            + "\n".join(cases) + "\n  </testsuite>\n</testsuites>\n")


def _detail(row):
    parts = [row["status"]]
    if row.get("message"):
        parts.append(row["message"])
    if row.get("compare_max") is not None:
        parts.append(f"distance to golden: max {row['compare_max']:.3g}, mean "
                     f"{_number(row.get('compare_mean'), '.3g')}, tol "
                     f"{_number(row.get('tol'), 'g')}")
    return "; ".join(parts)
