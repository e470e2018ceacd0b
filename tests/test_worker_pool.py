"""Jobs in worker processes: a worker that dies takes only its own job with it."""
import os
import subprocess
import sys

import pool_jobs
import pytest
import yaml
from helpers import ROOT

from srarap_cli.tasks.batch.worker_pool import death_note, run_in_processes


@pytest.mark.slow
@pytest.mark.parametrize("workers", [1, 2, 3])
def test_a_job_that_kills_its_worker_fails_alone_and_the_others_finish(tmp_path, workers):
    names = ["a", "b", "kill", "c", "d", "e"]
    rows = run_in_processes([(n, None) for n in names], pool_jobs.run, workers, pool_jobs.lost)
    assert [r["job"] for r in rows] == names
    assert rows[2] == {"job": "kill", "lost": -9}
    assert all("pid" in r for k, r in enumerate(rows) if k != 2)


def test_a_worker_killed_once_from_outside_costs_its_job_nothing(tmp_path):
    names = ["a", "kill-once", "b", "c"]
    jobs = [(n, str(tmp_path / "marker")) for n in names]
    rows = run_in_processes(jobs, pool_jobs.run, 2, pool_jobs.lost)
    assert [r["job"] for r in rows] == names and all("pid" in r for r in rows)
    assert (tmp_path / "marker").exists()  # the job did kill its first worker


def test_death_notes_name_the_signal_or_the_code():
    assert "SIGKILL" in death_note(-9) and "out of memory" in death_note(-9)
    assert death_note(-11).endswith("SIGSEGV")
    assert death_note(1) == "its worker process exited with code 1"


# the batch command with one job whose worker process is killed each time it runs it (as the
# out-of-memory killer would, every time, for a job too large for the machine): a
# sitecustomize, which every interpreter imports, so that workers get it however they start
# (forked from the batch or from a fork server)
KILL_HUGE = """
import os, signal
from srarap_cli.tasks.batch import run as batch
real = batch.run_job
def run_job(job, *args, **kwargs):
    if job.name == "huge":
        os.kill(os.getpid(), signal.SIGKILL)
    return real(job, *args, **kwargs)
batch.run_job = run_job
"""


@pytest.mark.slow
@pytest.mark.parametrize("extra", [[], ["--scheduler", "local"]])
def test_a_batch_whose_worker_is_killed_reports_that_job_failed_and_the_rest(tmp_path, extra):
    """Local worker processes, or a local Dask cluster (whose task for the job fails once
    its worker died twice: Dask's KilledWorker ended the batch as an internal error)."""
    if extra:
        pytest.importorskip("distributed")
    jobs = [{"name": n, "mesh": f"{ROOT}/sample_meshes/bar.obj",
             "handles": f"{ROOT}/configs/bar-twist.yaml", "output": f"{n}.obj"}
            for n in ("one", "huge", "two", "three")]
    (tmp_path / "jobs.yaml").write_text(yaml.safe_dump({"jobs": jobs}))
    (tmp_path / "hook").mkdir()
    (tmp_path / "hook" / "sitecustomize.py").write_text(KILL_HUGE)
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o", "out",
                        "--workers", "2", *extra], cwd=tmp_path, capture_output=True, timeout=300,
                       env={**os.environ, "PYTHONPATH": str(tmp_path / "hook")})
    err = p.stderr.decode()
    assert p.returncode == 8 and "Traceback" not in err and "internal error" not in err, err
    rows = {r["job"]: r for r in yaml.safe_load((tmp_path / "out" / "summary.json").read_text())}
    # a job Dask ran again because the worker that had its result died is up to date
    assert [rows[n]["status"] in ("ok", "up-to-date") for n in ("one", "two", "three")] == \
        [True] * 3
    assert rows["huge"]["status"] == "failed" and "worker process" in rows["huge"]["message"]
    if not extra:  # the pool knows how its worker ended
        assert rows["huge"]["exit_code"] == 137 and "killed by SIGKILL" in err
    assert sorted(os.listdir(tmp_path / "out")) == sorted(
        [f"{n}.obj{s}" for n in ("one", "two", "three") for s in ("", ".srarap.json")]
        + ["summary.csv", "summary.json"])
    assert "huge" in err
