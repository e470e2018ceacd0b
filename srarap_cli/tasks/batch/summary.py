"""A batch's account of its jobs: ``summary.csv`` and ``summary.json`` in the output folder,
and the HTML report, JUnit, the Markdown summary and the OpenMetrics file where asked."""
import csv
import io
import json
import os

from ...runtime.commit import commit_files
from ...runtime.encoding import utf8
from ..ci_summaries import openmetrics, summary_markdown
from ..job_status import SUMMARY_FIELDS, WARNING_JOIN, JobResult
from ..reports import junit_xml, report_html
from .manifest import SUMMARIES


def write_summaries(rows: list[JobResult], out: str) -> None:
    """``summary.csv`` and ``summary.json`` of ``rows`` in ``out``, committed together (and
    inside ``out``: a link there that leads out is refused)."""
    summary_rows = [r.row() for r in rows]
    texts = (summary_csv(summary_rows), json.dumps(summary_rows, indent=2) + "\n")
    commit_files([(os.path.join(out, name), utf8(text)) for name, text in zip(SUMMARIES, texts)],
                 inside=out)


def write_reports(rows: list[JobResult], manifest: str, report: str | None,
                  junit: str | None, markdown: str | None = None,
                  metrics: str | None = None) -> None:
    """The HTML report, the JUnit file, the Markdown summary and the OpenMetrics file, those
    asked for, committed together."""
    title = os.path.splitext(os.path.basename(manifest))[0]
    files = []
    if markdown is not None:
        files.append((markdown, utf8(summary_markdown(rows, f"srarap batch {title}"))))
    if metrics is not None:
        files.append((metrics, utf8(openmetrics(rows))))
    if report is not None:
        pictures = {r.job: r.pictures for r in rows}
        files.append((report, utf8(report_html(rows, pictures, f"srarap batch: {title}"))))
    if junit is not None:
        files.append((junit, utf8(junit_xml(rows, title))))
    commit_files(files)


def summary_csv(rows: list[dict]) -> str:
    """summary.csv: one line a job. A row with a lone carriage return in a field (a job's
    name or message) has every field quoted: the writer quotes only what holds its line
    terminator, and every CSV reader took the bare ``\r`` for the end of a row."""
    buf = io.StringIO()
    plain = csv.DictWriter(buf, fieldnames=SUMMARY_FIELDS, lineterminator="\n")
    quoted = csv.DictWriter(buf, fieldnames=SUMMARY_FIELDS, lineterminator="\n",
                            quoting=csv.QUOTE_ALL)
    plain.writeheader()
    for r in rows:
        row = {**r, "warnings": WARNING_JOIN.join(r["warnings"])}
        (quoted if any("\r" in str(v) for v in row.values()) else plain).writerow(row)
    return buf.getvalue()
