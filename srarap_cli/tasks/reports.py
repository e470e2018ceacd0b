"""What a batch did, for people and for CI systems: one self-contained HTML page (pictures
embedded, no script, nothing fetched) and JUnit XML.

Both are pure functions of the summary rows (and the pictures the workers drew), with no
timestamp or random id: two runs on identical inputs differ only in the seconds measured.
"""
import base64
import html
import math
import re
from collections.abc import Sequence
from xml.sax.saxutils import escape, quoteattr

from .job_status import JobResult, JobStatus

COLOURS = {"failed": "#c62828", "regressed": "#c62828", "no-golden": "#c62828",
           "not-converged": "#ef6c00",
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


def ordered(rows: Sequence[JobResult]) -> list[JobResult]:
    """Results in the order a reviewer needs them: failures and regressions first (manifest
    order within each status)."""
    rank = {s: k for k, s in enumerate(JobStatus)}
    return sorted(rows, key=lambda r: rank[r.status])


def number_text(value: float | int | None, fmt: str) -> str:
    """A figure as a report shows it: ``-`` where there is none (None, NaN)."""
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else format(value, fmt)


def percent_text(fraction: float | None) -> str:
    """A fraction as a percentage (``12%``), ``-`` where there is none."""
    return "-" if fraction is None else f"{100 * fraction:.3g}%"


def _seconds(value, fmt=".2f"):
    """Measured seconds, marked: the only text two reports of identical inputs differ in."""
    return f"<span class=\"seconds\">{number_text(value, fmt)}</span>"


def _summary(rows):
    counts = {s.value: sum(r.status is s for r in rows) for s in JobStatus}
    parts = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    seconds = sum(r.seconds or 0.0 for r in rows)
    compared = [r for r in rows if r.compare_max is not None]
    worst = max(compared, key=lambda r: r.compare_max, default=None)
    far = (f"; the largest distance to a golden mesh: {worst.compare_max:.3g} "
           f"({html.escape(worst.job)})" if worst else "")
    warned = sum(bool(r.warnings) for r in rows)
    warned_text = f"; {warned} with warnings" if warned else ""
    written = [r for r in rows if r.golden]
    goldens = ("; goldens written by this run: " + ", ".join(
        f"{html.escape(r.job)} ({r.golden})" for r in written) if written else "")
    return (f"<p class=\"summary\"><b>{len(rows)} jobs</b>: {parts}{warned_text}; "
            f"{_seconds(seconds, '.1f')} s of solving{far}{goldens}</p>")


def _job(row, pictures):
    status = row.status.value
    numbers = [("exit code", number_text(row.exit_code, "d")),
               ("stop", html.escape(row.stop or "-")),  # from a record: text, not markup
               ("iterations", number_text(row.iterations, "d")),
               ("seconds", _seconds(row.seconds)),
               ("energy", number_text(row.energy, ".6g")),
               ("to golden: max", number_text(row.compare_max, ".3g")),
               ("mean", number_text(row.compare_mean, ".3g")),
               ("p95", number_text(row.compare_p95, ".3g")),
               ("p99", number_text(row.compare_p99, ".3g")),
               ("beyond tol", percent_text(row.beyond_tol)),
               *([("A to B", number_text(row.compare_a_to_b, ".3g")),  # A: the golden
                  ("B to A", number_text(row.compare_b_to_a, ".3g"))]
                 if row.compare_a_to_b is not None else []),
               ("tolerance", number_text(row.tol, "g")),
               ("golden", html.escape(row.golden or "-")),
               ("warnings", str(len(row.warnings)))]
    table = ("<tr>" + "".join(f"<th>{k}</th>" for k, _ in numbers) + "</tr><tr>"
             + "".join(f"<td>{v}</td>" for _, v in numbers) + "</tr>")
    figures = "".join(
        f"<figure><img alt=\"{html.escape(caption)}\" src=\"data:image/png;base64,"
        f"{pictures[key]}\"><figcaption>{html.escape(caption)}</figcaption></figure>"
        for key, caption in PICTURES if key in pictures)
    message = "".join(f"<p class=\"message\">{html.escape(text)}</p>"
                      for text in (row.message, row.aligned and f"aligned first: {row.aligned}",
                                   pictures.get("note")) if text)
    warnings = ("<ul class=\"warnings\">" + "".join(
        f"<li>warning: {html.escape(w)}</li>" for w in row.warnings) + "</ul>"
        if row.warnings else "")
    return (f"<section class=\"job\" id=\"{html.escape(row.job, quote=True)}\"><h2>"
            f"{html.escape(row.job)} <span class=\"badge\" style=\"background:"
            f"{COLOURS.get(status, '#555')}\">{html.escape(status)}</span></h2>{message}"
            f"{warnings}<table>{table}</table>{figures}</section>")


def report_html(rows: Sequence[JobResult], pictures: dict[str, dict[str, str]],
                title: str) -> str:
    """The batch report: a summary, then one section per job, those needing a look first.

    Parameters
    ----------
    rows : list of JobResult
    pictures : dict job name -> dict picture name (``shape``, ``difference``, ``energy``) ->
        base64 PNG
    title : str, the page's heading (the manifest's name)
    """
    jobs = "".join(_job(r, pictures.get(r.job, {})) for r in ordered(rows))
    return ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>"
            f"<h1>{html.escape(title)}</h1>{_summary(rows)}{jobs}</body></html>\n")


def encode_png(data: bytes) -> str:
    """PNG bytes as the base64 text an ``<img src="data:...">`` holds."""
    return base64.b64encode(data).decode("ascii")


#: characters XML 1.0 does not allow, even escaped (and lone surrogates, which no encoder
#: writes): shown as ``\\xNN`` / ``\\uNNNN`` instead
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def xml_text(text: str) -> str:
    """``text`` with the characters XML 1.0 forbids written out visibly.

    Examples
    --------
    >>> xml_text("job\x01\x1b[31m")
    'job\\\\x01\\\\x1b[31m'
    """
    return _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}" if ord(m.group()) < 0x100
                        else f"\\u{ord(m.group()):04x}", text)


def _attr(text: str) -> str:
    return quoteattr(xml_text(text))


def junit_xml(rows: Sequence[JobResult], suite: str) -> str:
    """JUnit XML of a batch: one test case per job (class name ``srarap.<suite>``).

    A failed or interrupted job is an ``error``, a regressed or unconverged one a
    ``failure``, each with its text in ``message`` and in the element's body (what GitLab
    and Jenkins show); an up-to-date job passed (its recorded result stands: the property
    ``<job>.solved`` is ``false``). A job's warnings are its ``system-err`` and the property
    ``<job>.warnings`` counts them. Characters XML forbids in names and texts are written
    out (:func:`xml_text`), so the file parses whatever a job is called.
    """
    cases, failures, errors = [], 0, 0
    properties = []
    for r in rows:
        detail, inner = _detail(r), ""
        if r.status.unfinished:
            errors += 1
            inner = (f"<error type={_attr(r.status.value)} message={_attr(detail)}>"
                     f"{escape(xml_text(detail))}</error>")
        elif not r.status.passed:
            failures += 1
            inner = (f"<failure type={_attr(r.status.value)} message={_attr(detail)}>"
                     f"{escape(xml_text(detail))}</failure>")
        if r.warnings:
            inner += ("<system-err>" + escape(xml_text("".join(f"warning: {w}\n"
                                                               for w in r.warnings)))
                      + "</system-err>")
        properties.append(f"      <property name={_attr(r.job + '.warnings')} "
                          f"value=\"{len(r.warnings)}\"/>")
        if r.status is JobStatus.UP_TO_DATE:
            properties.append(f"      <property name={_attr(r.job + '.solved')} "
                              "value=\"false\"/>")
        cases.append(f"    <testcase name={_attr(r.job)} "
                     f"classname={_attr('srarap.' + suite)} "
                     f"time=\"{(r.seconds or 0.0):.3f}\">{inner}</testcase>")
    seconds = sum(r.seconds or 0.0 for r in rows)
    head = (f"tests=\"{len(rows)}\" failures=\"{failures}\" errors=\"{errors}\" "
            f"time=\"{seconds:.3f}\"")
    return ("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            f"<testsuites name={_attr(suite)} {head}>\n"
            f"  <testsuite name={_attr(suite)} {head} skipped=\"0\">\n"
            "    <properties>\n" + "\n".join(properties) + "\n    </properties>\n"
            + "\n".join(cases) + "\n  </testsuite>\n</testsuites>\n")


def _detail(row):
    parts = [row.status.value]
    if row.message:
        parts.append(row.message)
    if row.compare_max is not None:
        beyond = percent_text(row.beyond_tol)
        parts.append(f"distance to golden: max {row.compare_max:.3g}, mean "
                     f"{number_text(row.compare_mean, '.3g')}, p95 {number_text(row.compare_p95, '.3g')}"
                     f", p99 {number_text(row.compare_p99, '.3g')}, beyond tol {beyond}, tol "
                     f"{number_text(row.tol, 'g')}")
    if row.compare_a_to_b is not None:
        parts.append(f"one-sided: A to B max {row.compare_a_to_b:.3g}, B to A max "
                     f"{number_text(row.compare_b_to_a, '.3g')} (at every vertex)")
    if row.aligned:
        parts.append(f"aligned first: {row.aligned}")
    if row.golden:
        parts.append(f"golden {row.golden} by this run")
    if row.warnings:
        parts.append(f"{len(row.warnings)} warning(s)")
    return "; ".join(parts)
