"""What CI systems show where reviewers look: a Markdown summary (a GitHub job summary,
``$GITHUB_STEP_SUMMARY``) and an OpenMetrics ``metrics.txt`` (GitLab's merge-request
widget compares it between a branch and its target). Both are pure functions of the jobs'
results, like the report and JUnit (:mod:`.reports`).

The metric names are a contract: :data:`METRICS` lists them, and they stay as they are
across versions (a renamed metric would show in GitLab as one removed and one added).
"""
import math
from collections.abc import Callable, Sequence

from .job_status import JobResult
from .reports import number_text, ordered, percent_text

#: name -> (help, unit or "", the figure of a result); one sample per job and metric, NaN
#: where a job has no such figure (it failed before solving, it has no golden)
METRICS: dict[str, tuple[str, str, Callable[[JobResult], float | int | None]]] = {
    "srarap_job_passed": ("1 when the job passed (ok or up to date), else 0", "",
                          lambda r: int(r.status.passed)),
    "srarap_job_iterations": ("iterations of the job's solve (recorded for an up-to-date job)",
                              "", lambda r: r.iterations),
    "srarap_job_seconds": ("wall seconds of the job in this run", "seconds",
                           lambda r: r.seconds),
    "srarap_job_energy": ("the solve's final energy (membrane plus bending)", "",
                          lambda r: r.energy),
    "srarap_job_golden_distance_max": ("largest distance to the golden mesh, in the unit of "
                                       "the job's tol", "", lambda r: r.compare_max),
    "srarap_job_golden_distance_p95": ("95th percentile distance to the golden mesh, in the "
                                       "unit of the job's tol", "", lambda r: r.compare_p95),
    "srarap_job_golden_beyond_tol_ratio": ("fraction of the vertices farther than tol from "
                                           "the golden mesh", "ratio", lambda r: r.beyond_tol),
}
#: the columns of the Markdown table: heading, alignment, the cell of a result
_COLUMNS: tuple[tuple[str, str, Callable[[JobResult], str]], ...] = (
    ("job", "---", lambda r: _text(r.job)),
    ("status", "---", lambda r: f"**{r.status.value}**" if not r.status.passed
     else r.status.value),
    ("golden", "---", lambda r: r.golden or "-"),
    ("iterations", "--:", lambda r: number_text(r.iterations, "d")),
    ("seconds", "--:", lambda r: number_text(r.seconds, ".2f")),
    ("energy", "--:", lambda r: number_text(r.energy, ".4g")),
    ("max distance", "--:", lambda r: number_text(r.compare_max, ".3g")),
    ("p95", "--:", lambda r: number_text(r.compare_p95, ".3g")),
    ("beyond tol", "--:", lambda r: percent_text(r.beyond_tol)),
    ("tol", "--:", lambda r: number_text(r.tol, "g")),
    ("warnings", "--:", lambda r: str(len(r.warnings))),
    ("message", "---", lambda r: _text(r.message) if r.message else ""),
)
#: what Markdown would read as markup in a job's name or message: escaped (CommonMark lets
#: a backslash escape any ASCII punctuation), so the text shows as it is and links nothing
_MARKUP = set("\\`*_[]<>|#!~&")


def summary_markdown(rows: Sequence[JobResult], title: str) -> str:
    """A GitHub-flavoured Markdown summary: a heading with the counts, then one table row a
    job, those needing a look first; no link, no picture (a job summary shows text)."""
    counts: dict[str, int] = {}
    for r in rows:
        counts[r.status.value] = counts.get(r.status.value, 0) + 1
    failing = sum(not r.status.passed for r in rows)
    verdict = "all passed" if not failing else f"{failing} need a look"
    lines = [f"### {_text(title)}: {len(rows)} jobs, {verdict}", "",
             ", ".join(f"{n} {s}" for s, n in counts.items()), "",
             "| " + " | ".join(h for h, _, _ in _COLUMNS) + " |",
             "|" + "|".join(a for _, a, _ in _COLUMNS) + "|"]
    lines += ["| " + " | ".join(cell(r) for _, _, cell in _COLUMNS) + " |" for r in ordered(rows)]
    written = [r for r in rows if r.golden]
    if written:
        lines += ["", "Goldens written by this run: " + ", ".join(
            f"{_text(r.job)} ({r.golden})" for r in written) + "."]
    return "\n".join(lines) + "\n"


def openmetrics(rows: Sequence[JobResult]) -> str:
    """The jobs' figures in the OpenMetrics text format (one gauge family per metric of
    :data:`METRICS`, one sample per job, labelled ``job``; ended by ``# EOF``)."""
    out = []
    for name, (help_text, unit, figure) in METRICS.items():
        out.append(f"# TYPE {name} gauge")
        if unit:
            out.append(f"# UNIT {name} {unit}")
        out.append(f"# HELP {name} {help_text}")
        out += [f"{name}{{job=\"{_label(r.job)}\"}} {_sample(figure(r))}" for r in rows]
    return "\n".join(out) + "\n# EOF\n"


def _text(text: str) -> str:
    """A name or message as one table cell: markup escaped, lines joined."""
    flat = " ".join(str(text).split())
    return "".join("\\" + c if c in _MARKUP else c for c in flat)


def _label(text: str) -> str:
    return text.replace("\\", "\\\\").replace("\"", "\\\"").replace("\n", "\\n")


def _sample(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "NaN"
    if isinstance(value, float) and math.isinf(value):
        return "+Inf" if value > 0 else "-Inf"
    return repr(value) if isinstance(value, float) else str(int(value))
