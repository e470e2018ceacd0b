"""Stages said as they begin and end (``runtime/stages.py``) and the heartbeat that names
them in a log while nothing else is said (``cli/progress.py``)."""
import time

import pytest

from srarap_cli.cli.progress import SolveProgress
from srarap_cli.runtime import stages


def test_a_nested_level_names_its_stages_in_the_lines_and_the_running_list():
    heard = []
    with stages.heard_by(lambda name, seconds: heard.append(name)):
        stages.begun("setup")
        with stages.deeper():
            stages.begun("multires: simplify")
            assert [name for name, _ in stages.running()] == [
                "setup", "coarse level 1: multires: simplify"]
            stages.ended("multires: simplify", 1.0)
        stages.ended("setup", 2.0)
    assert heard == ["coarse level 1: multires: simplify", "setup"]
    assert stages.running() == []


def test_forget_clears_what_a_failed_job_left_running():
    stages.begun("read")
    stages.forget()
    assert stages.running() == []


def test_a_log_gets_a_heartbeat_naming_the_stage_while_it_runs(capsys, monkeypatch):
    monkeypatch.setenv("SRARAP_PROGRESS_EVERY", "0.05")
    progress = SolveProgress(enabled=True, terminal=False)
    try:
        with stages.deeper():
            stages.begun("multires: simplify")
            time.sleep(0.6)  # several intervals: the heartbeat has its turn whatever the load
            stages.ended("multires: simplify", 0.6)
    finally:
        progress.close()
    lines = capsys.readouterr().err.splitlines()
    assert any(line.startswith("srarap: progress: coarse level 1: multires: simplify ")
               for line in lines), lines
    assert all(line.startswith("srarap: progress: ") for line in lines)


def test_quiet_has_no_heartbeat(capsys, monkeypatch):
    monkeypatch.setenv("SRARAP_PROGRESS_EVERY", "0.05")
    progress = SolveProgress(enabled=False, terminal=False)
    stages.begun("setup")
    time.sleep(0.3)
    stages.ended("setup", 0.3)
    progress.close()
    assert capsys.readouterr().err == ""


@pytest.mark.slow  # three batches in processes of their own
def test_a_batch_log_names_each_long_jobs_stages_in_process_and_in_workers(tmp_path):
    import json
    import os
    import subprocess
    import sys

    from helpers import ROOT
    bar, twist = f"{ROOT}/sample_meshes/bar.obj", f"{ROOT}/configs/bar-twist.yaml"
    manifest = tmp_path / "m.yaml"
    manifest.write_text(json.dumps({"jobs": [{"name": f"j{k}", "mesh": bar, "handles": twist,
                                              "output": f"j{k}.obj"} for k in range(2)]}))
    for extra in ([], ["--workers", "2"], ["-q"]):
        p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", str(manifest), "-o",
                            str(tmp_path / f"out{len(extra)}{extra[:1]}"), *extra],
                           capture_output=True, text=True, timeout=600,
                           env={**os.environ, "SRARAP_PROGRESS_EVERY": "0.01"})
        assert p.returncode == 0, p.stderr
        beats = [line for line in p.stderr.splitlines() if line.startswith("srarap: progress:")]
        if extra == ["-q"]:
            assert beats == []
        else:
            assert {line.split("'")[1] for line in beats} == {"j0", "j1"}, p.stderr
