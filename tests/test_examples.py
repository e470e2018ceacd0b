"""Every example in examples/ runs as its comments say, in an empty folder."""
import os
import shutil
import subprocess
import sys

import pytest
import yaml
from helpers import ROOT

EXAMPLES = os.path.join(ROOT, "examples")
BINDIR = os.path.dirname(sys.executable)  # srarap and python3 of this environment
ENV = {**os.environ, "PATH": BINDIR + os.pathsep + os.environ["PATH"]}


def run(cmd, cwd, **kwargs):
    return subprocess.run(cmd, cwd=cwd, env=ENV, capture_output=True, text=True, timeout=600,
                          **kwargs)


@pytest.mark.slow
def test_the_makefile_pipeline_builds_checks_and_catches_drift(tmp_path):
    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    shutil.copy(os.path.join(EXAMPLES, "pipeline", "Makefile"), tmp_path)
    p = run(["make", "-j2", "all", "check"], tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    for job in ("bar-twist", "bar-bend", "spot-nod"):
        assert (tmp_path / "out" / f"{job}.obj").exists() and (tmp_path / "out" / f"{job}.csv").exists()
    assert (tmp_path / "out" / "energy.png").stat().st_size > 0
    assert "Nothing to be done" in run(["make"], tmp_path).stdout  # up to date: no rerun
    golden = tmp_path / "samples" / "golden" / "bar-bend.obj"
    golden.write_text(golden.read_text().replace("\nv ", "\nv 0.01 0 0 #", 1))
    p = run(["make", "check"], tmp_path)
    assert p.returncode != 0 and "BEYOND" in p.stderr


def workflow_steps():
    with open(os.path.join(EXAMPLES, "ci-regression", "mesh-regression.yml")) as fh:
        flow = yaml.safe_load(fh)
    return [s for s in flow["jobs"]["regression"]["steps"] if "run" in s]


@pytest.mark.slow
def test_the_ci_workflow_passes_and_fails_on_drift(tmp_path):
    """The workflow's run steps in order, as GitHub runs them (bash -e), except the install
    step: srarap is installed here already. It publishes what its later steps upload."""
    steps = [s for s in workflow_steps() if s["name"] != "Install srarap"]
    assert [s["name"] for s in steps] == ["Deform and compare with the goldens", "Job summary"]
    summary = tmp_path / "step_summary"
    summary.write_text("")  # GitHub gives each step an empty file
    for step in steps:
        p = subprocess.run(["bash", "-e", "-c", step["run"]], cwd=tmp_path, capture_output=True,
                           text=True, timeout=600,
                           env={**ENV, "GITHUB_STEP_SUMMARY": str(summary)})
        assert p.returncode == 0, p.stderr
    assert summary.read_text().startswith("### srarap batch example-jobs: 2 jobs, all passed")
    uploads = [s["with"] for s in yaml.safe_load(open(os.path.join(
        EXAMPLES, "ci-regression", "mesh-regression.yml")))["jobs"]["regression"]["steps"]
        if "with" in s and ("path" in s["with"] or "report_paths" in s["with"])]
    for published in uploads:
        assert (tmp_path / published.get("path", published.get("report_paths"))).is_file()
    junit = (tmp_path / "out" / "junit.xml").read_text()
    assert 'failures="0"' in junit and 'errors="0"' in junit
    assert "strict: true" in (tmp_path / "meshes" / "configs" / "example-jobs.yaml").read_text()
    # a golden that drifted: the step fails and the report shows that job first
    golden = tmp_path / "meshes" / "golden" / "bar-twist.obj"
    golden.write_text(golden.read_text().replace("\nv ", "\nv 0.01 0 0 #", 1))
    p = run(["bash", "-e", "-c", "srarap batch meshes/configs/example-jobs.yaml -o out "
             "--report out/report.html --junit out/junit.xml"], tmp_path)
    assert p.returncode == 8 and "regressed" in p.stderr
    html = (tmp_path / "out" / "report.html").read_text()
    first = html.index('<section class="job"')
    assert html[first:].startswith('<section class="job" id="bar-twist">')
    assert "distance to the golden mesh" in html[first:html.index("</section>", first)]
    assert '<failure type="regressed"' in (tmp_path / "out" / "junit.xml").read_text()


@pytest.mark.slow
def test_the_api_script_deforms_a_trimesh_mesh(tmp_path):
    pytest.importorskip("trimesh")
    assert run(["srarap", "samples", "samples", "-q"], tmp_path).returncode == 0
    script = os.path.join(EXAMPLES, "api", "deform_with_trimesh.py")
    p = run([sys.executable, script, "samples/sample_meshes/spot.obj", "spot-nod.ply"], tmp_path)
    assert p.returncode == 0 and "converged" in p.stdout, p.stderr
    assert p.stderr == ""  # no warning: the welded mesh is one closed surface
    from srarap_cli.io.mesh import read_mesh
    assert len(read_mesh(str(tmp_path / "spot-nod.ply")).vertices) == 11533


@pytest.mark.slow
@pytest.mark.parametrize("how", [["--workers", "2"], ["--scheduler", "local", "--workers", "2"]])
def test_the_batch_manifest_runs_locally_and_on_dask(tmp_path, how):
    if "--scheduler" in how:
        pytest.importorskip("distributed")
    shutil.copy(os.path.join(EXAMPLES, "batch", "jobs.yaml"), tmp_path)
    assert run(["srarap", "samples", ".", "-q"], tmp_path).returncode == 0
    p = run(["srarap", "batch", "jobs.yaml", "-o", "out", *how], tmp_path)
    assert p.returncode == 0 and "4 jobs: 4 ok" in p.stderr, p.stderr
    written = sorted(f for f in os.listdir(tmp_path / "out") if not f.endswith(".srarap.json"))
    assert written == ["bar-bend-stiff.obj", "bar-bend.obj", "bar-twist.obj", "spot-nod.ply",
                       "summary.csv", "summary.json"]


def test_the_batch_manifest_commands_are_the_ones_its_comments_give():
    text = open(os.path.join(EXAMPLES, "batch", "jobs.yaml")).read()
    assert "srarap batch jobs.yaml -o out --workers 2" in text
    assert "srarap batch jobs.yaml -o out-dask --scheduler local --workers 2" in text


@pytest.mark.slow
def test_the_gitlab_file_writes_what_its_reports_name(tmp_path):
    """The GitLab file's script, as GitLab runs it (bash -e), except its before_script (the
    install): every artifact and report it names is written; metrics.txt reads as
    OpenMetrics, one sample per job and metric."""
    from prometheus_client.openmetrics.parser import text_string_to_metric_families

    with open(os.path.join(EXAMPLES, "ci-regression", "gitlab-ci.yml")) as fh:
        job = yaml.safe_load(fh)["mesh-regression"]
    p = run(["bash", "-e", "-c", "\n".join(job["script"])], tmp_path)
    assert p.returncode == 0, p.stderr
    artifacts = job["artifacts"]
    for path in [*artifacts["paths"], *artifacts["reports"].values()]:
        assert (tmp_path / path).is_file(), path
    families = list(text_string_to_metric_families(
        (tmp_path / artifacts["reports"]["metrics"]).read_text()))
    assert len(families) == 7
    assert all([s.labels["job"] for s in f.samples] == ["bar-twist", "bar-bend-paper"]
               for f in families)
