"""What CI systems show (``tasks/ci_summaries.py``): the Markdown summary read by a
GitHub-flavoured Markdown parser (a table, failures first, names shown as written, no link),
and the metrics file read by an OpenMetrics parser (one sample per job and metric, the names
a contract)."""
import math

import pytest
from markdown_it import MarkdownIt
from prometheus_client.openmetrics.parser import text_string_to_metric_families

from srarap_cli.tasks.ci_summaries import METRICS, openmetrics, summary_markdown
from srarap_cli.tasks.job_status import JobResult, JobStatus

ROWS = [
    JobResult("ok | one", JobStatus.OK, 0, iterations=9, energy=3.5, seconds=0.5,
              compare_max=0.0, compare_p95=0.0, beyond_tol=0.0, tol=1e-6),
    JobResult("drift*", JobStatus.REGRESSED, 7, iterations=12, energy=3.6, seconds=0.7,
              compare_max=2e-3, compare_p95=1e-3, beyond_tol=0.5, tol=1e-6,
              message="max distance 0.002 > tol 1e-06 <b>x</b> [a](http://x)", golden="updated"),
    JobResult("new\njob\\\"", JobStatus.NO_GOLDEN, 8, iterations=3, energy=1.0, seconds=0.1),
    JobResult("broken", JobStatus.FAILED, 4, message="bad.obj: no such file"),
]


def test_the_markdown_summary_is_a_table_failures_first_text_as_written():
    text = summary_markdown(ROWS, "srarap batch jobs")
    gfm = MarkdownIt("commonmark").enable("table")  # GitHub's tables (GFM's extension)
    tokens = gfm.parse(text)
    assert [t.type for t in tokens if t.type in ("table_open", "link_open", "image")] == \
        ["table_open"]
    html = gfm.render(text)
    assert "<script" not in html and "<b>" not in html and "&lt;b&gt;x&lt;/b&gt;" in html
    rows = [line for line in html.split("<tr>")[2:]]
    assert len(rows) == len(ROWS)
    cells = [[c.split("</td>")[0] for c in row.split("<td")[1:]] for row in rows]
    names = [c[0].split(">", 1)[1] for c in cells]
    assert names == ["broken", "drift*", "new job\\&quot;", "ok | one"]  # failures first
    header = html.split("<tr>")[1]
    assert header.count("<th") == len(cells[0]) == 12
    assert "<strong>regressed</strong>" in html and "Goldens written by this run: drift" in html
    assert text.startswith("### srarap batch jobs: 4 jobs, 3 need a look\n")


def test_the_metrics_file_is_openmetrics_one_sample_per_job_and_metric():
    text = openmetrics(ROWS)
    families = {f.name: f for f in text_string_to_metric_families(text)}
    assert set(families) == set(METRICS)
    assert families["srarap_job_seconds"].unit == "seconds"
    for name, family in families.items():
        assert family.type == "gauge"
        jobs = [s.labels["job"] for s in family.samples]
        assert jobs == [r.job for r in ROWS], name
    by_job = {s.labels["job"]: s.value for s in families["srarap_job_iterations"].samples}
    assert by_job["ok | one"] == 9 and math.isnan(by_job["broken"])
    passed = {s.labels["job"]: s.value for s in families["srarap_job_passed"].samples}
    assert passed == {"ok | one": 1, "drift*": 0, "new\njob\\\"": 0, "broken": 0}


def test_the_metric_names_stay_as_they_are():
    """GitLab compares metrics by name between a branch and its target: a renamed metric
    shows as one removed and one added. These names are the documented contract."""
    assert list(METRICS) == ["srarap_job_passed", "srarap_job_iterations", "srarap_job_seconds",
                             "srarap_job_energy", "srarap_job_golden_distance_max",
                             "srarap_job_golden_distance_p95",
                             "srarap_job_golden_beyond_tol_ratio"]


@pytest.mark.parametrize("value, text", [(None, "NaN"), (float("inf"), "+Inf"), (3, "3"),
                                         (0.25, "0.25")])
def test_samples_are_written_as_openmetrics_numbers(value, text):
    row = JobResult("j", JobStatus.OK, 0, iterations=value)
    line = next(s for s in openmetrics([row]).splitlines()
                if s.startswith("srarap_job_iterations{"))
    assert line == f'srarap_job_iterations{{job="j"}} {text}'
