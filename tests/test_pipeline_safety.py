"""A failed or unconverged run must not look like a finished one to make, batch or a script."""
import json
import os
import re
import shutil
import subprocess
import sys

import pytest
from helpers import ROOT, stderr_on_a_terminal, tube_mesh

from srarap_cli.io.mesh import write_mesh

HANDLES = ("groups:\n  base: {box: {min: [-2, -2, -0.01], max: [2, 2, 0.01]}, fixed: true}\n"
           "  tip: {box: {min: [-2, -2, 5.99], max: [2, 2, 6.01]}, rotate: "
           "{axis: [0, 0, 1], angle_deg: 90}}\n")


@pytest.fixture
def folder(tmp_path):
    write_mesh(str(tmp_path / "m.obj"), tube_mesh(rings=12, segments=8))
    (tmp_path / "h.yaml").write_text(HANDLES)
    return tmp_path


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make is not installed")
def test_make_fails_on_an_unconverged_run_and_fails_again_on_the_rerun(folder):
    srarap = f"{sys.executable} -m srarap_cli"
    (folder / "Makefile").write_text(
        f"out.obj: m.obj h.yaml\n\t{srarap} deform m.obj h.yaml -o out.obj --max-iter 2 -q\n"
        f"good.obj: m.obj h.yaml\n\t{srarap} deform m.obj h.yaml -o good.obj -q\n")
    for _ in range(2):
        p = subprocess.run(["make", "out.obj"], cwd=folder, capture_output=True, text=True,
                           timeout=300)
        assert p.returncode != 0 and not (folder / "out.obj").exists(), p.stdout + p.stderr
    assert subprocess.run(["make", "good.obj"], cwd=folder, capture_output=True,
                          timeout=300).returncode == 0
    again = subprocess.run(["make", "good.obj"], cwd=folder, capture_output=True, text=True,
                           timeout=300)
    assert again.returncode == 0 and "up to date" in again.stdout


def test_keep_unconverged_writes_the_mesh_and_still_exits_3(folder):
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml", "-o",
                        "o.obj", "--max-iter", "2", "--log", "o.csv", "--keep-unconverged"],
                       cwd=folder, capture_output=True, text=True, timeout=300)
    assert p.returncode == 3 and (folder / "o.obj").exists() and (folder / "o.csv").exists()
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml", "-o",
                        "p.obj", "--max-iter", "2", "--log", "p.csv"],
                       cwd=folder, capture_output=True, text=True, timeout=300)
    assert p.returncode == 3 and not (folder / "p.obj").exists() and (folder / "p.csv").exists()
    assert "no mesh written" in p.stderr and "raise --max-iter" in p.stderr


def batch(folder, settings, *extra):
    (folder / "jobs.yaml").write_text(
        f"jobs:\n  - {{mesh: m.obj, handles: h.yaml, output: a.obj, settings: {settings}}}\n")
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", "jobs.yaml", "-o", "out",
                        *extra], cwd=folder, capture_output=True, text=True, timeout=300)
    rows = json.loads((folder / "out" / "summary.json").read_text())
    return p.returncode, rows[0]["status"]


@pytest.mark.slow
def test_batch_remembers_a_job_that_did_not_converge(folder):
    assert batch(folder, "{max_iter: 2}") == (3, "not-converged")
    assert not (folder / "out" / "a.obj").exists()  # exit 3 writes no mesh, as deform
    assert batch(folder, "{max_iter: 2}") == (3, "not-converged")  # nothing changed
    assert not (folder / "out" / "a.obj").exists()
    assert batch(folder, "{max_iter: 2}", "--keep-unconverged") == (3, "not-converged")
    assert (folder / "out" / "a.obj").exists()
    assert batch(folder, "{max_iter: 1000}") == (0, "ok")  # settings changed: run again
    assert batch(folder, "{max_iter: 1000}") == (0, "up-to-date")


@pytest.mark.slow
def test_the_shipped_batch_example_passes_as_written(tmp_path):
    path = os.path.join(ROOT, "configs", "example-jobs.yaml")
    p = subprocess.run([sys.executable, "-m", "srarap_cli", "batch", path, "-o",
                        str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    rows = json.loads((tmp_path / "summary.json").read_text())
    assert [r["status"] for r in rows] == ["ok"] * len(rows)


@pytest.mark.slow
def test_standard_input_and_output_with_formats(folder):
    ref = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "m.obj", "h.yaml", "-o",
                          "ref.obj", "-q"], cwd=folder, capture_output=True, timeout=300)
    assert ref.returncode == 0
    with open(folder / "m.obj", "rb") as fh:
        p = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "-", "h.yaml", "-o",
                            "-", "--format", "obj", "--input-format", "obj"], cwd=folder,
                           stdin=fh, capture_output=True, timeout=300)
    assert p.returncode == 0 and p.stdout == (folder / "ref.obj").read_bytes()
    assert b"wrote <stdout>" in p.stderr
    for args, code in ((["--input-format", "ply"], 4), ([], 4)):
        bad = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", "-", "h.yaml", "-o",
                              "-", "--format", "ply", *args], cwd=folder, input=b"garbage",
                             capture_output=True, timeout=300)
        assert bad.returncode == code and bad.stdout == b"" and bad.stderr.count(b"\n") == 1


@pytest.mark.slow
def test_a_long_deform_shows_progress_on_a_terminal_only(tmp_path):
    spot = os.path.join(ROOT, "sample_meshes", "spot.obj")
    nod = os.path.join(ROOT, "configs", "spot-nod.yaml")
    cmd = [sys.executable, "-m", "srarap_cli", "deform", spot, nod, "-o", str(tmp_path / "o.obj"),
           "--accel", "none", "--start", "laplacian", "--tol", "0", "--max-iter", "150"]
    text = stderr_on_a_terminal(cmd)
    # each redraw clears the line first (a shorter line left the longer one's tail)
    assert "\r\x1b[Kiteration " in text and "energy " in text and "change " in text
    # a log's lines come every SRARAP_PROGRESS_EVERY seconds, which a loaded machine can
    # reach within 150 iterations: none asked for here, the redraws are what is checked
    piped = subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=600,
                           env={**os.environ, "SRARAP_PROGRESS_EVERY": "100000"})
    assert "\riteration" not in piped.stderr and "srarap deform:" in piped.stderr
    assert "srarap: progress:" not in piped.stderr


def test_a_log_shows_the_warnings_then_progress_lines_before_the_solve_ends(tmp_path):
    """Issue 60: with stderr to a file (a CI log) nothing came until the process ended, and a
    warning known before the solve came after it. Now the warning first, then progress lines
    (here every 0.05 s) naming the level, then the summary."""
    spot = os.path.join(ROOT, "sample_meshes", "spot.obj")
    nod = open(os.path.join(ROOT, "configs", "spot-nod.yaml")).read()
    (tmp_path / "h.yaml").write_text(nod.replace("angle_deg: -30", "angle_rad: 30"))
    with open(tmp_path / "log.txt", "w") as log:
        done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", spot, "h.yaml",
                               "-o", "o.obj", "--multires", "1000"], cwd=tmp_path,
                              stderr=log, timeout=600,
                              env={**os.environ, "SRARAP_PROGRESS_EVERY": "0.05"})
    assert done.returncode == 0
    lines = (tmp_path / "log.txt").read_text().splitlines()
    warned = next(k for k, line in enumerate(lines) if "more than a full turn" in line)
    progress = [k for k, line in enumerate(lines) if line.startswith("srarap: progress: ")]
    rows = [k for k in progress if "iteration" in lines[k]]  # the solve's own lines
    summary = next(k for k, line in enumerate(lines) if line.startswith("srarap deform: "))
    assert rows and warned < rows[0] and progress[-1] < summary == len(lines) - 1
    # before the solve, the heartbeat names the stage it is in (issue 70)
    assert all(re.fullmatch(r"srarap: progress: ([a-z][\w :,-]* \d+\.\d s(; )?)+  "
                            r"\(\d+\.\d s in all\)", lines[k])
               for k in progress if k not in rows), lines
    assert any("coarse mesh, iteration" in lines[k] for k in progress)
    assert any("full resolution, iteration" in lines[k] for k in progress)
    assert sum("more than a full turn" in line for line in lines) == 1  # said once
    quiet = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", spot, "h.yaml", "-o",
                            "q.obj", "--multires", "1000", "-q"], cwd=tmp_path, text=True,
                           capture_output=True, timeout=600,
                           env={**os.environ, "SRARAP_PROGRESS_EVERY": "0.05"})
    assert "progress" not in quiet.stderr and "more than a full turn" in quiet.stderr


def test_a_verbose_log_says_each_stage_as_it_ends(tmp_path):
    """Issue 60: ``-v``'s stage lines came after the solve. Now each as its stage ends: the
    reading and the checks before any progress line, the coarse solve's line before the
    full-resolution iterations' progress, the write's last, before the summary."""
    spot = os.path.join(ROOT, "sample_meshes", "spot.obj")
    nod = os.path.join(ROOT, "configs", "spot-nod.yaml")
    with open(tmp_path / "log.txt", "w") as log:
        done = subprocess.run([sys.executable, "-m", "srarap_cli", "deform", spot, nod,
                               "-o", "o.obj", "--multires", "1000", "-v"], cwd=tmp_path,
                              stderr=log, timeout=600,
                              env={**os.environ, "SRARAP_PROGRESS_EVERY": "0.05"})
    assert done.returncode == 0
    lines = (tmp_path / "log.txt").read_text().splitlines()
    at = {line.split(": ", 2)[2].rsplit(" ", 2)[0]: k for k, line in enumerate(lines)
          if line.startswith("srarap: stage: ")}
    order = ["read", "checks", "multires: simplify", "setup", "multires: coarse solve",
             "multires: full-resolution iterations", "solve", "write"]
    assert [at[name] for name in order] == sorted(at[name] for name in order), lines
    progress = [k for k, line in enumerate(lines) if line.startswith("srarap: progress: ")]
    rows = [k for k in progress if "iteration" in lines[k]]  # (the others: the heartbeat)
    fine = [k for k in progress if "full resolution, iteration" in lines[k]]
    assert at["checks"] < rows[0] and fine and at["multires: coarse solve"] < fine[0]
    assert at["write"] < next(k for k, line in enumerate(lines)
                              if line.startswith("srarap deform: "))


def test_an_animation_log_shows_warnings_first_then_frames_as_they_are_written(tmp_path):
    bar = os.path.join(ROOT, "sample_meshes", "bar.obj")
    keys = os.path.join(ROOT, "configs", "bar-twist-animated.yaml")
    with open(tmp_path / "log.txt", "w") as log:
        done = subprocess.run([sys.executable, "-m", "srarap_cli", "animate", bar, keys, "-o",
                               "f_{:03d}.obj", "--frames", "20"], cwd=tmp_path, stderr=log,
                              timeout=600, env={**os.environ, "SRARAP_PROGRESS_EVERY": "0.01"})
    assert done.returncode == 0
    lines = (tmp_path / "log.txt").read_text().splitlines()
    warned = next(k for k, line in enumerate(lines) if "[unreached-keys]" in line)
    frames = [k for k, line in enumerate(lines) if line.startswith("srarap: progress: frame ")]
    assert frames and warned < frames[0] and frames[-1] == len(lines) - 2
    assert "frame 20/20" in lines[frames[-1]] and lines[-1].startswith("srarap animate: ")
    assert sum("[unreached-keys]" in line for line in lines) == 1
