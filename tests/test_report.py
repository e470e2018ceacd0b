"""CI regression people can look at and CI systems can read: batch/compare --report (one
self-contained HTML file) and --junit (JUnit XML as Jenkins' junit-10 schema has it)."""
import base64
import json
import os
import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml
from browser import find_chromium, open_pages
from click.testing import CliRunner
from helpers import ROOT

from srarap_cli.cli import main
from srarap_cli.tasks.job_status import JobResult, JobStatus
from srarap_cli.tasks.reports import junit_xml, report_html

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
CONFIGS = os.path.join(ROOT, "configs")
GOLDEN = os.path.join(ROOT, "golden")
PNG = b"\x89PNG\r\n\x1a\n"


def manifest(tmp_path):
    """Three jobs: one made to regress (alpha changed against its golden), one ok, one
    whose mesh is missing."""
    jobs = [{"name": "twist-regressed", "mesh": BAR, "handles": os.path.join(CONFIGS, "bar-twist.yaml"),
             "output": "twist.obj", "settings": {"alpha": 0.5},
             "expect": {"golden": os.path.join(GOLDEN, "bar-twist.obj"), "tol": 1e-6,
                        "relative": True}},
            {"name": "bend-ok", "mesh": BAR, "handles": os.path.join(CONFIGS, "bar-bend.yaml"),
             "output": "bend.obj", "settings": {"method": "sr-linear", "handle_rotors": "lagged"},
             "expect": {"golden": os.path.join(GOLDEN, "bar-bend-paper.obj"), "tol": 1e-6,
                        "relative": True}},
            {"name": "broken", "mesh": str(tmp_path / "missing.obj"),
             "handles": os.path.join(CONFIGS, "bar-bend.yaml"), "output": "broken.obj"}]
    path = tmp_path / "ci.yaml"
    path.write_text(yaml.safe_dump({"defaults": {"tol": 1e-9, "max_iter": 3000}, "jobs": jobs}))
    return path


def batch(path, out, *extra):
    return CliRunner().invoke(main, ["batch", str(path), "-o", str(out), "-q",
                                     "--report", str(out / "report.html"),
                                     "--junit", str(out / "junit.xml"), *extra])


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ci")
    path = manifest(tmp)
    r = batch(path, tmp / "out")
    assert r.exit_code == 8, r.stderr  # a failed and a regressed job
    return tmp, path


def sections(html):
    return re.findall(r'<section class="job" id="([^"]+)">(.*?)</section>', html, re.DOTALL)


def test_the_report_puts_the_failures_first_with_their_numbers_and_pictures(run):
    tmp, _ = run
    html = (tmp / "out" / "report.html").read_text()
    jobs = sections(html)
    assert [name for name, _ in jobs] == ["broken", "twist-regressed", "bend-ok"]
    regressed = jobs[1][1]
    assert "regressed" in regressed and "1e-06" in regressed and "beyond tol" in regressed
    images = dict(re.findall(r'<img alt="([^"]+)" src="data:image/png;base64,([^"]+)"',
                             regressed))
    assert set(images) == {"rest (ghosted) and result, handles coloured",
                           "distance to the golden mesh", "energy per iteration"}
    assert all(base64.b64decode(data).startswith(PNG) for data in images.values())
    summary = html[html.index('class="summary"'):html.index("</p>", html.index('class="summary"'))]
    assert "3 jobs" in summary and "1 failed" in summary and "1 regressed" in summary
    assert "twist-regressed" in summary  # the worst distance names its job


def test_the_report_is_self_contained(run):
    tmp, _ = run
    html = (tmp / "out" / "report.html").read_text()
    assert "<script" not in html.lower()
    assert not re.search(r'(src|href)="(?!data:|#)', html)  # nothing fetched from anywhere


@pytest.mark.slow
def test_two_runs_on_identical_inputs_differ_only_in_the_seconds(tmp_path):
    path = manifest(tmp_path)
    texts = []
    for k in range(2):
        batch(path, tmp_path / f"out{k}")
        html = (tmp_path / f"out{k}" / "report.html").read_text()
        texts.append(re.sub(r'<span class="seconds">[^<]*</span>', "", html))
        junit = (tmp_path / f"out{k}" / "junit.xml").read_text()
        texts.append(re.sub(r'time="[0-9.]+"', "", junit))
    assert texts[0] == texts[2] and texts[1] == texts[3]


# Jenkins' xUnit plugin schema junit-10.xsd, as rules (GitLab, GitHub's test reporters and
# Buildkite read the same elements): testsuites > testsuite (name, tests, failures and errors
# required; time a decimal) > testcase (name required) > at most failure / error / skipped /
# system-out / system-err, each with only type and message attributes; a testsuite may hold
# properties (each property with exactly name and value).
SUITE_REQUIRED = {"name", "tests", "failures", "errors"}
SUITE_ALLOWED = SUITE_REQUIRED | {"group", "time", "skipped", "timestamp", "hostname", "id",
                                  "package", "file", "log", "url"}
CASE_ALLOWED = {"name", "time", "classname", "group"}
OUTCOME_ALLOWED = {"type", "message"}
TIME = re.compile(r"(([0-9]{0,3},)*[0-9]{3}|[0-9]{0,3})*(\.[0-9]*)?")


def check_junit(text):
    root = ET.fromstring(text)
    assert root.tag == "testsuites"
    assert set(root.attrib) <= {"name", "time", "tests", "failures", "errors"}
    counted = 0
    for suite in root:
        assert suite.tag == "testsuite"
        assert SUITE_REQUIRED <= set(suite.attrib) <= SUITE_ALLOWED
        assert TIME.fullmatch(suite.get("time", ""))
        assert all(c.tag in ("testcase", "properties", "system-out", "system-err")
                   for c in suite)
        for prop in suite.iter("property"):
            assert set(prop.attrib) == {"name", "value"}
        cases = suite.findall("testcase")
        for case in cases:
            assert "name" in case.attrib and set(case.attrib) <= CASE_ALLOWED
            for outcome in case:
                assert outcome.tag in ("failure", "error", "skipped", "system-out",
                                       "system-err")
                assert set(outcome.attrib) <= OUTCOME_ALLOWED
        assert int(suite.get("tests")) == len(cases)
        assert int(suite.get("failures")) == sum(c.find("failure") is not None for c in cases)
        assert int(suite.get("errors")) == sum(c.find("error") is not None for c in cases)
        counted += len(cases)
    return root


def test_junit_has_one_case_per_job_with_the_outcome_ci_systems_expect(run):
    tmp, path = run
    root = check_junit((tmp / "out" / "junit.xml").read_text())
    cases = {c.get("name"): c for c in root.iter("testcase")}
    assert set(cases) == {"twist-regressed", "bend-ok", "broken"}
    failure = cases["twist-regressed"].find("failure")
    # the text in the body too: GitLab and Jenkins show the body, not the attribute
    assert failure is not None and "tol 1e-06" in failure.get("message")
    assert "tol 1e-06" in failure.text and "beyond tol" in failure.text
    error = cases["broken"].find("error")
    assert error is not None and "missing.obj" in error.text
    assert len(cases["bend-ok"]) == 0
    # a second run: the unchanged jobs are up to date: passed, and said not solved again
    batch(path, tmp / "out")
    root = check_junit((tmp / "out" / "junit.xml").read_text())
    cases = {c.get("name"): c for c in root.iter("testcase")}
    assert len(cases["bend-ok"]) == 0 and root.find(".//skipped") is None
    props = {p.get("name"): p.get("value") for p in root.iter("property")}
    assert props["bend-ok.solved"] == "false" and props["bend-ok.warnings"] == "0"
    html = (tmp / "out" / "report.html").read_text()
    ok = dict(sections(html))["bend-ok"]
    assert "up-to-date" in ok and "data:image/png" in ok  # drawn from its files


def test_the_schema_rules_catch_what_ci_systems_refuse():
    good = junit_xml([JobResult("a", JobStatus.OK, 0, seconds=1.0)], "s")
    check_junit(good)
    with pytest.raises(AssertionError):
        check_junit(good.replace(' failures="0"', "", 1).replace(' failures="0"', ""))
    with pytest.raises(AssertionError):
        check_junit(good.replace('<testcase name="a"', "<testcase"))


def test_compare_names_where_the_difference_is_and_writes_its_report(tmp_path):
    a, b = str(tmp_path / "a.obj"), str(tmp_path / "b.obj")
    r = CliRunner().invoke(main, ["deform", BAR, os.path.join(CONFIGS, "bar-bend.yaml"),
                                  "-o", a, "-q"])
    assert r.exit_code == 0
    shutil.copy(BAR, b)
    r = CliRunner().invoke(main, ["compare", a, b, "--tol", "0.01", "--relative",
                                  "--json", str(tmp_path / "c.json"),
                                  "--report", str(tmp_path / "c.html"),
                                  "--junit", str(tmp_path / "c.xml")])
    assert r.exit_code == 7
    figures = json.loads((tmp_path / "c.json").read_text())
    far = figures["farthest"]
    assert far["mesh"] == "a" and 0 < figures["beyond_tol"] <= 1
    from srarap_cli.io.mesh import read_mesh
    A, B = read_mesh(a).vertices, read_mesh(b).vertices
    d = ((A - B) ** 2).sum(axis=1) ** 0.5
    assert far["vertex"] == int(d.argmax()) and far["position"] == A[far["vertex"]].tolist()
    assert abs(figures["beyond_tol"] - float((d / figures["diagonal"] > 0.01).mean())) < 1e-12
    assert f"vertex {far['vertex']}" in r.stderr
    check_junit((tmp_path / "c.xml").read_text())
    assert "distance to the golden mesh" in (tmp_path / "c.html").read_text()


@pytest.mark.slow  # starts a browser
def test_a_report_of_100_jobs_stays_small_and_opens_in_a_browser(run, tmp_path):
    tmp, _ = run
    html = (tmp / "out" / "report.html").read_text()
    one = dict(sections(html))["twist-regressed"]
    pictures = dict(zip(("shape", "difference", "energy"),
                        re.findall(r'src="data:image/png;base64,([^"]+)"', one)))
    rows = [JobResult(f"job-{k:03d}", JobStatus.REGRESSED if k % 10 == 0 else JobStatus.OK,
                      7 if k % 10 == 0 else 0, stop="converged", iterations=10, seconds=0.5,
                      energy=1.0, compare_max=1e-3, compare_mean=1e-4, tol=1e-6)
            for k in range(100)]
    page = report_html(rows, {r.job: pictures for r in rows}, "100 jobs")
    report = tmp_path / "report.html"
    report.write_text(page)
    assert len(page) < 20e6
    chromium = find_chromium()
    shot = Path(os.environ.get("SRARAP_SCREENSHOTS", tmp_path)) / "batch-report.png"
    shown, errors = open_pages(chromium, tmp_path, ["report.html"], tmp_path,
                               screenshot=("report.html", shot))
    assert not errors, errors
    assert len(pictures) >= 2 and shown == {"report.html": 100 * len(pictures)}  # all loaded
    assert shot.is_file() and shot.stat().st_size > 20_000


def test_a_picture_that_cannot_be_drawn_is_said_in_the_report_not_hidden():
    row = JobResult("j", JobStatus.OK, 0, seconds=1.0)
    page = report_html([row], {"j": {"note": "pictures not drawn: ValueError: bad mesh"}}, "t")
    assert "pictures not drawn: ValueError: bad mesh" in page and "<img" not in page
