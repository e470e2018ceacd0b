"""``srarap batch``: failures isolated, up-to-date jobs skipped, goldens checked."""
import csv
import os

import pytest
import yaml
from click.testing import CliRunner
from helpers import ROOT

from srarap_cli.cli import main
from srarap_cli.io.mesh import read_mesh, write_mesh

BAR = os.path.join(ROOT, "sample_meshes", "bar.obj")
BEND = os.path.join(ROOT, "configs", "bar-bend.yaml")
TWIST = os.path.join(ROOT, "configs", "bar-twist.yaml")


def manifest(tmp_path, jobs, defaults=None):
    path = tmp_path / "jobs.yaml"
    path.write_text(yaml.safe_dump({"defaults": defaults or {"max_iter": 300}, "jobs": jobs}))
    return path


def run(path, out, *extra):
    r = CliRunner().invoke(main, ["batch", str(path), "-o", str(out), *extra])
    with open(out / "summary.csv") as fh:
        return r, {row["job"]: row for row in csv.DictReader(fh)}


def test_a_broken_job_is_reported_and_the_rest_run_then_nothing_reruns(tmp_path):
    jobs = [{"name": "twist", "mesh": BAR, "handles": TWIST, "output": "twist.obj"},
            {"name": "broken", "mesh": str(tmp_path / "missing.obj"), "handles": BEND,
             "output": "broken.obj"},
            {"name": "bend", "mesh": BAR, "handles": BEND, "output": "sub/bend.ply"}]
    out = tmp_path / "out"
    r, rows = run(manifest(tmp_path, jobs), out, "--workers", "2")
    assert r.exit_code == 8
    assert [rows[j]["status"] for j in ("twist", "broken", "bend")] == ["ok", "failed", "ok"]
    assert "missing.obj" in rows["broken"]["message"]
    first = (out / "twist.obj").read_bytes()
    assert len(read_mesh(str(out / "sub" / "bend.ply")).vertices) == len(read_mesh(BAR).vertices)
    r, rows = run(manifest(tmp_path, jobs), out, "--workers", "2")
    assert [rows[j]["status"] for j in ("twist", "bend")] == ["up-to-date", "up-to-date"]
    assert rows["twist"]["iterations"] and (out / "twist.obj").read_bytes() == first
    r, rows = run(manifest(tmp_path, jobs[:1]), out)
    assert r.exit_code == 0 and "nothing to solve: all up to date" in r.stderr
    r, rows = run(manifest(tmp_path, jobs[:1], {"max_iter": 301}), out)
    assert rows["twist"]["status"] == "ok"  # settings changed: solved again


def test_parallel_and_sequential_runs_write_the_same_bytes(tmp_path):
    jobs = [{"name": n, "mesh": BAR, "handles": h, "output": f"{n}.obj"}
            for n, h in (("twist", TWIST), ("bend", BEND))]
    run(manifest(tmp_path, jobs), tmp_path / "seq")
    run(manifest(tmp_path, jobs), tmp_path / "par", "--workers", "2")
    for n in ("twist", "bend"):
        assert (tmp_path / "seq" / f"{n}.obj").read_bytes() == (tmp_path / "par" / f"{n}.obj").read_bytes()


def test_a_result_away_from_its_golden_is_a_regression(tmp_path):
    golden = tmp_path / "golden.obj"
    m = read_mesh(BAR)
    write_mesh(str(golden), m.with_vertices(m.vertices + [0.0, 0.0, 0.01]))
    jobs = [{"name": "bend", "mesh": BAR, "handles": BEND, "output": "bend.obj",
             "expect": {"golden": str(golden), "tol": 1e-3, "relative": True}}]
    r, rows = run(manifest(tmp_path, jobs), tmp_path / "out")
    assert r.exit_code == 8 and rows["bend"]["status"] == "regressed"
    assert float(rows["bend"]["compare_max"]) > 1e-3


def test_bad_manifest_is_invalid_input(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump({"jobs": [{"mesh": BAR, "output": "x.obj"}]}))
    r = CliRunner().invoke(main, ["batch", str(path), "-o", str(tmp_path)])
    assert r.exit_code == 4 and "needs mesh, handles and output" in r.stderr


@pytest.mark.slow
def test_a_dask_cluster_gives_the_same_results_as_local_workers(tmp_path):
    from distributed import LocalCluster

    jobs = [{"name": n, "mesh": BAR, "handles": h, "output": f"{n}.obj"}
            for n, h in (("twist", TWIST), ("bend", BEND))]
    jobs.append({"name": "broken", "mesh": str(tmp_path / "missing.obj"), "handles": BEND,
                 "output": "broken.obj"})
    path = manifest(tmp_path, jobs)
    local, local_rows = run(path, tmp_path / "local", "--workers", "2")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        remote, remote_rows = run(path, tmp_path / "dask", "--scheduler",
                                  cluster.scheduler_address)
    assert local.exit_code == remote.exit_code == 8
    assert {k: r["status"] for k, r in remote_rows.items()} == \
        {k: r["status"] for k, r in local_rows.items()}
    for n in ("twist", "bend"):
        assert (tmp_path / "dask" / f"{n}.obj").read_bytes() == \
            (tmp_path / "local" / f"{n}.obj").read_bytes()
        assert remote_rows[n]["iterations"] == local_rows[n]["iterations"]


@pytest.mark.slow
def test_scheduler_local_starts_single_threaded_workers_without_dasks_trim_setting(tmp_path):
    """``--scheduler local``: the same bytes as local workers; its workers run one BLAS
    thread and glibc's own malloc trimming (Dask's nanny default slowed solves 1.8x), without
    Dask's statistical profiler (its samples took CPU from the solves)."""
    import functools
    import os

    import dask

    from srarap_cli.tasks.batch.on_dask import run_on_dask

    jobs = [{"name": "twist", "mesh": BAR, "handles": TWIST, "output": "twist.obj"}]
    path = manifest(tmp_path, jobs)
    run(path, tmp_path / "local")
    dask_run, _ = run(path, tmp_path / "dask", "--scheduler", "local", "--workers", "2")
    assert dask_run.exit_code == 0, dask_run.output
    assert (tmp_path / "dask" / "twist.obj").read_bytes() == \
        (tmp_path / "local" / "twist.obj").read_bytes()
    probe = functools.partial(lambda job, out_dir: (
        os.environ.get("MALLOC_TRIM_THRESHOLD_"), os.environ.get("OPENBLAS_NUM_THREADS"),
        dask.config.get("distributed.worker.profile.enabled")), out_dir=str(tmp_path))
    assert run_on_dask([{}, {}], probe, "local", 2) == [(None, "1", False)] * 2
    assert dask.config.get("distributed.worker.profile.enabled")  # this process: as it was


def test_editing_a_file_the_handle_file_names_makes_the_job_run_again(tmp_path):
    (tmp_path / "move.def").write_text("1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    (tmp_path / "h.yaml").write_text(yaml.safe_dump({"groups": {
        "base": {"box": {"min": [-2, -2, -0.01], "max": [2, 2, 0.01]}, "fixed": True},
        "top": {"box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, "matrix": "move.def"}}}))
    jobs = [{"name": "m", "mesh": BAR, "handles": str(tmp_path / "h.yaml"), "output": "m.obj"}]
    path = manifest(tmp_path, jobs)
    assert run(path, tmp_path / "out")[1]["m"]["status"] == "ok"
    assert run(path, tmp_path / "out")[1]["m"]["status"] == "up-to-date"
    (tmp_path / "move.def").write_text("1 0 0 0.7\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    assert run(path, tmp_path / "out")[1]["m"]["status"] == "ok"


def test_changing_only_the_strictness_judges_the_record_again_without_solving(tmp_path):
    """Issue 70: a rerun with only --strict/--allow changed solved every job again. The
    strictness decides nothing in a mesh: the recorded warnings are judged again."""
    h = tmp_path / "slip.yaml"  # a forgotten fixed group: a [rigid-part] warning
    h.write_text(yaml.safe_dump({"groups": {"top": {
        "box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, "translate": [1, 0, 0]}}}))
    path = manifest(tmp_path, [{"name": "slip", "mesh": BAR, "handles": str(h),
                                "output": "slip.obj"}])
    out = tmp_path / "out"
    r, rows = run(path, out)
    assert r.exit_code == 0 and rows["slip"]["status"] == "ok"
    made = (out / "slip.obj").stat().st_mtime_ns
    r, rows = run(path, out, "--strict")
    assert r.exit_code == 8 and rows["slip"]["status"] == "failed"
    assert rows["slip"]["exit_code"] == "4" and "[rigid-part]" in rows["slip"]["message"]
    assert "strict: warnings about the request are errors" in rows["slip"]["message"]
    r, rows = run(path, out, "--strict", "--allow", "rigid-part")
    assert r.exit_code == 0 and rows["slip"]["status"] == "up-to-date"
    assert (out / "slip.obj").stat().st_mtime_ns == made  # never solved again
    strict_in_file = tmp_path / "strict.yaml"
    strict_in_file.write_text(h.read_text() + "solver: {strict: true}\n")
    path = manifest(tmp_path, [{"name": "slip", "mesh": BAR, "handles": str(strict_in_file),
                                "output": "slip.obj"}])
    r, rows = run(path, out)  # another handle file: solved, and failed by its own strict
    assert r.exit_code == 8 and rows["slip"]["status"] == "failed"


def test_the_codes_allow_accepts_add_up_over_defaults_job_and_command_line(tmp_path):
    """Issue 72: a job's own ``allow`` replaced the defaults' (``{**defaults, **job}``),
    while the docs and ``resolve`` add them up. Here only the defaults' code accepts the
    job's warning; the job's and the command line's codes are others."""
    h = tmp_path / "slip.yaml"  # a forgotten fixed group: a [rigid-part] warning
    h.write_text(yaml.safe_dump({"groups": {"top": {
        "box": {"min": [-2, -2, 9.99], "max": [2, 2, 10.01]}, "translate": [1, 0, 0]}}}))
    job = {"name": "slip", "mesh": BAR, "handles": str(h), "output": "slip.obj",
           "settings": {"allow": ["needles"]}}
    path = manifest(tmp_path, [job], {"strict": True, "allow": ["rigid-part"]})
    r, rows = run(path, tmp_path / "out", "--allow", "units")
    assert r.exit_code == 0 and rows["slip"]["status"] == "ok", rows["slip"]["message"]
    path = manifest(tmp_path, [job], {"strict": True})  # without it: failed by strict
    r, rows = run(path, tmp_path / "out2", "--allow", "units")
    assert rows["slip"]["status"] == "failed" and "[rigid-part]" in rows["slip"]["message"]


def test_a_batch_is_one_frozen_job_and_one_call_from_python(tmp_path):
    """Issue 72: ``run_batch(BatchJob) -> BatchOutcome``, the path the command takes; the
    manifest's jobs are typed, with their settings as layers laid in one place."""
    import dataclasses

    from srarap_cli.tasks.batch import BatchJob, load_manifest, run_batch

    path = manifest(tmp_path, [{"name": "twist", "mesh": BAR, "handles": TWIST,
                                "output": "twist.obj", "settings": {"allow": ["needles"],
                                                                   "tol": 1e-5}}],
                    {"max_iter": 300, "allow": ["units"], "tol": 1e-4})
    job = load_manifest(str(path))[0]
    assert job.layers == ({"max_iter": 300, "allow": ("units",), "tol": 1e-4},
                          {"allow": ("needles",), "tol": 1e-5})
    assert job.over({"allow": ("rigid-part",), "strict": None}).settings == {
        "max_iter": 300, "allow": ("units", "needles", "rigid-part"), "tol": 1e-5}
    batch = BatchJob(str(path), str(tmp_path / "out"), settings={"strict": True})
    with pytest.raises(dataclasses.FrozenInstanceError):
        batch.workers = 2  # type: ignore[misc]
    for wrong, error in (({"workers": 0}, ValueError), ({"workers": 2.5}, ValueError),
                         ({"threads": True}, ValueError), ({"goldens": "sometimes"}, ValueError),
                         ({"settings": ["strict"]}, TypeError), ({"report": 3}, TypeError)):
        with pytest.raises(error, match="BatchJob"):
            BatchJob(str(path), **wrong)
    done = run_batch(batch)
    assert (done.exit_code, done.stopped, done.failure) == (0, None, None)
    assert [(r.job, r.status.value) for r in done.rows] == [("twist", "ok")]
    assert done.rows[0].seen.mesh is None  # shipped: what the run saw stays in its process
    assert (tmp_path / "out" / "summary.csv").exists()
    assert run_batch(batch).rows[0].status.value == "up-to-date"


def test_a_report_that_cannot_be_written_comes_after_the_summary(tmp_path, monkeypatch):
    """A report path refused before any job runs; one whose write fails after the jobs
    (a full disk: here a write that raises) is the outcome's failure, the summary written
    first."""
    from srarap_cli.runtime.errors import OutputError
    from srarap_cli.tasks.batch import BatchJob, run_batch
    from srarap_cli.tasks.batch import job as batch_job

    path = manifest(tmp_path, [{"name": "twist", "mesh": BAR, "handles": TWIST,
                                "output": "twist.obj"}])
    (tmp_path / "blocker").write_text("a file where the report's folder would be")
    with pytest.raises(OutputError, match="blocker is a file"):
        run_batch(BatchJob(str(path), str(tmp_path / "out"),
                           junit=str(tmp_path / "blocker" / "junit.xml")))
    assert not (tmp_path / "out").exists()

    def full_disk(*args, **kwargs):
        raise OutputError("junit.xml: No space left on device")
    monkeypatch.setattr(batch_job, "write_reports", full_disk)
    done = run_batch(BatchJob(str(path), str(tmp_path / "out"),
                              junit=str(tmp_path / "junit.xml")))
    assert done.failure is not None and "No space" in str(done.failure)
    assert [r.status.value for r in done.rows] == ["ok"]
    assert (tmp_path / "out" / "summary.json").exists()
